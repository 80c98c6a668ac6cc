"""A run's own ``trajectory.tum`` and ``reference.tum`` scored as files when its scans share timestamps.

The corrected Radish logs stamp every scan 0 (belgioioso, csail, freiburg-campus, infinite-corridor,
orebro), so a run's TUM files repeat their stamps: real repeats, not a rounding of the 9 decimals.
``albot1 evaluate --trajectory RUN/trajectory.tum --reference RUN/reference.tum`` (or ``--dataset NAME``)
refused them, though the run itself scores (scan by scan); now the file pairs line by line with the
other file's lines (the dataset's scans) when their stamps are the same and both are the files of one run
folder (of that dataset reference): equal stamps alone do not prove equal scans.
"""

from __future__ import annotations

import re
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from albot1.data.model import Frame, Scan, Sequence
from albot1.data.trajectory import read_tum, write_tum
from albot1.geometry import se2
from albot1.runs.errors import RunError
from albot1.runs.evaluate import evaluate_pair, evaluate_run, evaluate_trajectory
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

N = 130
#: every block a pair of trajectory files scores (relations, map, updates, cost need what the files lack)
SCORED_ALIKE = ("ate", "ate_windows", "rpe", "drift", "loop_gap", "orientation")


def _circle_stamped_zero() -> Sequence:
    """1 m and 3 deg per scan (a 120 m circle, driven 1.1 times), turns over-reported by 1 %; every scan at t = 0."""
    steps = np.tile([[1.0, 0.0, np.radians(3.0)]], (N - 1, 1))
    truth = se2.integrate_steps(np.zeros(3), steps)
    odometry = se2.integrate_steps(np.zeros(3), steps * [1.0, 1.0, 1.01])
    angles = np.linspace(-np.pi / 2, np.pi / 2, 31)
    frames = [Frame(i, Scan(np.full(31, 2.0), angles, 0.0, 8.0), odometry[i], truth[i]) for i in range(N)]
    return Sequence.from_frames("circle-stamped-zero", frames)


@pytest.fixture
def run_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The odometry's run folder; the dataset opens by its name (as a catalog dataset would)."""
    sequence = _circle_stamped_zero()
    monkeypatch.setattr("albot1.runs.external.open_sequence", lambda ref, **_: sequence)
    return write_run(run_method("odometry", sequence, dataset_name="circle-stamped-zero"), tmp_path)


def test_a_runs_own_files_with_repeated_stamps_score_the_runs_own_numbers(run_dir: Path) -> None:
    stamps, _ = read_tum(run_dir / "trajectory.tum")
    assert stamps.tolist() == [0.0] * N  # the repeats are the scans' own stamps
    from_run = evaluate_run(run_dir)
    from_files, _ = evaluate_pair(run_dir / "trajectory.tum", run_dir / "reference.tum")
    for name in SCORED_ALIKE:
        assert from_files.block(name) is not None, name
        assert from_files.block(name) == from_run.block(name), name  # every number equal, not close
    source = from_files.trajectory
    assert source is not None
    assert (source.poses, source.matched, source.unmatched, source.duplicates) == (N, N, 0, 0)
    assert (source.max_dt_s, source.reference_without_pose) == (None, 0)  # paired by line, as for KITTI


def test_a_runs_trajectory_with_repeated_stamps_scored_against_its_dataset_gives_the_runs_numbers(
    run_dir: Path,
) -> None:
    from_run = evaluate_run(run_dir)
    from_file, _ = evaluate_trajectory(run_dir / "trajectory.tum", "circle-stamped-zero")
    for name in SCORED_ALIKE:
        assert from_file.block(name) is not None, name
        assert from_file.block(name) == from_run.block(name), name
    source = from_file.trajectory
    assert source is not None and (source.matched, source.max_dt_s, source.reference_without_pose) == (N, None, 0)


def _refusal(path: Path, poses: int, others: str) -> str:
    """The one line that refuses a file whose stamps repeat (every stamp here is 0: one distinct value)."""
    return re.escape(
        f"{path}: {poses} poses for {others}, and its timestamps repeat (1 distinct value), so the poses cannot be "
        "matched by time; only a run's own files in its run folder pair line by line: to score a run, give "
        "`albot1 evaluate RUN_DIR`"
    )


def test_repeated_stamps_the_other_file_does_not_share_are_refused_with_the_counts(
    run_dir: Path, tmp_path: Path
) -> None:
    stamps, poses = read_tum(run_dir / "trajectory.tum")
    other = tmp_path / "other.tum"
    write_tum(other, stamps[:-1], poses[:-1])  # one line fewer: not the same scans line for line
    with pytest.raises(RunError, match=_refusal(other, N - 1, f"{N} reference poses of {run_dir / 'reference.tum'}")):
        evaluate_pair(other, run_dir / "reference.tum")
    with pytest.raises(
        RunError, match=_refusal(run_dir / "trajectory.tum", N, f"{N} reference poses of {run_dir / 'reference.tum'}")
    ):
        evaluate_pair(run_dir / "trajectory.tum", run_dir / "reference.tum", time_offset_s=0.5)
    with pytest.raises(RunError, match=_refusal(other, N - 1, f"{N} scans of 'circle-stamped-zero'")):
        evaluate_trajectory(other, "circle-stamped-zero")


def test_equal_repeated_stamps_of_another_selection_are_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every stamp 0: a run on every other scan and one on the first half hold equal stamps, not equal scans."""
    sequence = _circle_stamped_zero()
    frames = list(sequence)

    def renumbered(chosen: list[Frame]) -> Sequence:
        return Sequence.from_frames("circle-stamped-zero", [replace(f, index=i) for i, f in enumerate(chosen)])

    halves = {"circle-stamped-zero[::2]": renumbered(frames[::2]), "circle-stamped-zero[:65]": renumbered(frames[:65])}
    monkeypatch.setattr("albot1.runs.external.open_sequence", lambda ref, **_: halves[ref])
    every_other = write_run(
        run_method("odometry", halves["circle-stamped-zero[::2]"], dataset_name="circle-stamped-zero[::2]"),
        tmp_path / "a",
    )
    first_half = write_run(
        run_method("odometry", halves["circle-stamped-zero[:65]"], dataset_name="circle-stamped-zero[:65]"),
        tmp_path / "b",
    )
    trajectory, reference = every_other / "trajectory.tum", first_half / "reference.tum"
    assert np.array_equal(read_tum(trajectory)[0], read_tum(reference)[0])  # 65 stamps, all 0, on both sides
    with pytest.raises(RunError, match=_refusal(trajectory, 65, f"65 reference poses of {reference}")):
        evaluate_pair(trajectory, reference)
    with pytest.raises(RunError, match=_refusal(trajectory, 65, "65 scans of 'circle-stamped-zero[:65]'")):
        evaluate_trajectory(trajectory, "circle-stamped-zero[:65]")
    # the run's own dataset reference still pairs, and gives the run's numbers
    from_file, _ = evaluate_trajectory(trajectory, "circle-stamped-zero[::2]")
    assert from_file.block("ate") == evaluate_run(every_other).block("ate")


def test_a_runs_trajectory_copied_out_of_its_folder_is_refused(run_dir: Path, tmp_path: Path) -> None:
    copy = tmp_path / "copy" / "trajectory.tum"
    copy.parent.mkdir()
    shutil.copyfile(run_dir / "trajectory.tum", copy)
    with pytest.raises(RunError, match=_refusal(copy, N, f"{N} reference poses of {run_dir / 'reference.tum'}")):
        evaluate_pair(copy, run_dir / "reference.tum")
    with pytest.raises(RunError, match=_refusal(copy, N, f"{N} scans of 'circle-stamped-zero'")):
        evaluate_trajectory(copy, "circle-stamped-zero")
    renamed = run_dir / "mine.tum"  # beside the run's files, but not one the run wrote
    shutil.copyfile(run_dir / "trajectory.tum", renamed)
    with pytest.raises(RunError, match=_refusal(renamed, N, f"{N} scans of 'circle-stamped-zero'")):
        evaluate_trajectory(renamed, "circle-stamped-zero")
