"""An external trajectory's relation metric: relations are looked up at the scans its poses were matched to.

A relation names two scans by their stamps (within 0.1 ms); a trajectory's pose is matched to a scan within
``--max-dt`` (0.01 s). A file whose stamps are its scans' own but printed with 3 decimals, or a little late,
scores every pose for ATE; its relations must be scored on those same poses, not left out as if the file had
no pose for their scans (which scored a subset of the relations under the reason "the run did not see them").
"""

from __future__ import annotations

import hashlib
import logging
from pathlib import Path

import numpy as np
import pytest

from albot1.data.model import Frame, Relations, Scan, Sequence
from albot1.data.trajectory import write_tum
from albot1.geometry import se2
from albot1.metrics.record import MetricsRecord
from albot1.runs.evaluate import evaluate_run, evaluate_trajectory
from albot1.runs.external_run import external_config, write_external_run

N = 60


def _square_walk() -> Sequence:
    """0.5 m and 6 deg per scan, scans 0.1 s apart with sub-millisecond stamps, four relations of known error."""
    steps = np.tile([[0.5, 0.0, np.radians(6.0)]], (N - 1, 1))
    truth = se2.integrate_steps(np.zeros(3), steps)
    stamps = 100.0 + 0.1 * np.arange(N) + 0.000437  # 3 decimals round every stamp by 0.437 ms
    angles = np.linspace(-np.pi / 2, np.pi / 2, 31)
    frames = [Frame(i, Scan(np.full(31, 2.0), angles, stamps[i], 8.0), truth[i], truth[i]) for i in range(N)]
    i, j = np.array([0, 10, 20, 30]), np.array([5, 25, 40, 59])
    motion = se2.between(truth[i], truth[j])
    motion[1, 0] += 0.3  # relation 2 is 0.3 m off the truth, so a perfect trajectory scores (0, 0.3, 0, 0)
    return Sequence.from_frames("walk", frames, relations=Relations(stamps[i], stamps[j], motion))


@pytest.fixture
def walk(monkeypatch: pytest.MonkeyPatch) -> Sequence:
    sequence = _square_walk()
    monkeypatch.setattr("albot1.runs.external.open_sequence", lambda ref, **_: sequence)
    return sequence


@pytest.mark.parametrize(
    ("name", "shift"),
    [("rounded", "round"), ("late by 0.5 ms", 0.0005), ("early by 2 ms", -0.002)],
)
def test_relations_are_scored_on_every_matched_pose_whatever_its_stamps_precision(
    tmp_path: Path, walk: Sequence, name: str, shift: object
) -> None:
    truth = walk.arrays.reference
    assert truth is not None
    stamps = np.round(walk.timestamps, 3) if shift == "round" else walk.timestamps + float(shift)  # type: ignore[arg-type]
    write_tum(tmp_path / "t.tum", stamps, truth)
    record, _ = evaluate_trajectory(tmp_path / "t.tum", "walk")
    assert record.trajectory is not None and record.trajectory.matched == N, name
    relations = record.relations
    assert relations is not None, record.reason("relations")
    assert (relations.relations_used, relations.relations_outside_run) == (4, 0), name
    assert relations.translation_m.mean == pytest.approx(0.3 / 4, abs=1e-7)
    assert relations.translation_m.max == pytest.approx(0.3, abs=1e-7)


def test_relations_naming_scans_the_file_has_no_pose_for_are_counted_out(tmp_path: Path, walk: Sequence) -> None:
    truth = walk.arrays.reference
    assert truth is not None
    keep = np.delete(np.arange(N), [5, 59])  # relations 0 and 3 end at scans the file has no pose for
    write_tum(tmp_path / "gaps.tum", walk.timestamps[keep], truth[keep])
    record, _ = evaluate_trajectory(tmp_path / "gaps.tum", "walk")
    relations = record.relations
    assert relations is not None
    assert (relations.relations_used, relations.relations_outside_run) == (2, 2)
    assert relations.translation_m.mean == pytest.approx(0.15, abs=1e-7)  # relations 1 and 2: 0.3 m and 0 m


def test_a_suites_external_run_folder_reproduces_its_relation_metric(
    tmp_path: Path, walk: Sequence, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The bench stores an external file's matched poses; evaluating that folder again gives the same relations.

    Before, the stored poses kept the file's stamps (3 decimals here) and the folder's re-evaluation scored
    none of the relations, so the report left external runs out of every paired relation comparison.
    """
    monkeypatch.setattr("albot1.runs.external_run.open_sequence", lambda ref, **_: walk)
    truth = walk.arrays.reference
    assert truth is not None
    path = tmp_path / "mine.tum"
    write_tum(path, np.round(walk.timestamps, 3), truth)
    sha256 = hashlib.sha256(path.read_bytes()).hexdigest()
    run_dir = write_external_run(
        path=path,
        format_name=None,
        dataset="walk",
        method="mine",
        config=external_config(path, None, sha256),
        seed=0,
        runs_root=tmp_path / "runs",
    )
    stored = MetricsRecord.model_validate_json((run_dir / "metrics.json").read_text(encoding="utf-8"))
    assert stored.relations is not None and stored.relations.relations_used == 4
    again = evaluate_run(run_dir)
    assert again.relations == stored.relations


def test_repeated_relation_lines_are_not_warned_about_again_for_a_temporary_copy(
    tmp_path: Path, walk: Sequence, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """The warning names the dataset's file; the copy scoring reads back was named too, a path the user never saw."""
    relations = walk.relations
    assert relations is not None
    twice = Relations(
        np.r_[relations.t1, relations.t1[:1]],
        np.r_[relations.t2, relations.t2[:1]],
        np.r_[relations.poses, relations.poses[:1]],
        repeats=1,
        repeats_counted=True,
    )
    walk.relations = twice
    truth = walk.arrays.reference
    assert truth is not None
    write_tum(tmp_path / "t.tum", walk.timestamps, truth)
    with caplog.at_level(logging.WARNING):
        record, _ = evaluate_trajectory(tmp_path / "t.tum", "walk")
    assert record.relations is not None and record.relations.relations_used == 5
    assert not [r.getMessage() for r in caplog.records if "albot1-relations-" in r.getMessage()]
