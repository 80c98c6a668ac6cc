"""Two trajectory files scored against each other (albot1.runs.pair), checked against evo's own functions."""

from __future__ import annotations

import copy
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from albot1.data.trajectory import write_tum
from albot1.errors import Albot1Error
from albot1.runs.evaluate import evaluate_pair
from albot1.runs.pair import parse_alignment

# Found, not imported, at collection: evo (with scipy, ~0.2 s) is imported by the test that compares with it.
pytestmark = pytest.mark.skipif(importlib.util.find_spec("evo") is None, reason="evo is not installed")


def _write_repr_tum(path: Path, stamps: np.ndarray, poses: np.ndarray) -> None:
    """A TUM file written with repr() digits, so evo and albot1 read the very same numbers."""
    lines = []
    for t, (x, y, yaw) in zip(stamps, poses, strict=True):
        qz, qw = float(np.sin(yaw / 2)), float(np.cos(yaw / 2))
        lines.append(f"{float(t)!r} {float(x)!r} {float(y)!r} 0.0 0.0 0.0 {qz!r} {qw!r}")
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture
def files(tmp_path: Path) -> tuple[Path, Path]:
    """A curved reference and a noisy, drifting, rotated estimate whose clock is 0.3 s behind; 5 poses missing."""
    rng = np.random.default_rng(7)
    t = np.arange(300) * 0.1 + 1000.0
    s = t - t[0]
    ref = np.column_stack([6 * np.cos(s / 5), 4 * np.sin(s / 4), s / 5 + np.pi / 2])
    drift = np.column_stack([0.01 * s, -0.004 * s, 0.002 * s])
    est = ref + drift + rng.normal(0, 0.03, ref.shape)
    c, si = np.cos(0.4), np.sin(0.4)
    est_xy = est[:, :2] @ np.array([[c, si], [-si, c]]) + [3.0, -2.0]
    est = np.column_stack([est_xy, est[:, 2] + 0.4])
    jitter = rng.uniform(-0.003, 0.003, len(t))
    _write_repr_tum(tmp_path / "gt.tum", t, ref)
    _write_repr_tum(tmp_path / "est.tum", (t + jitter - 0.3)[5:], est[5:])
    return tmp_path / "est.tum", tmp_path / "gt.tum"


def _evo_ape(est_path: Path, ref_path: Path, offset: float, how: str, n: int | None = None) -> tuple[float, int]:
    from evo.core import metrics as evo_metrics
    from evo.core import sync as evo_sync
    from evo.tools import file_interface

    ref = file_interface.read_tum_trajectory_file(str(ref_path))
    est = file_interface.read_tum_trajectory_file(str(est_path))
    ref, est = evo_sync.associate_trajectories(ref, est, max_diff=0.01, offset_2=offset)
    est = copy.deepcopy(est)
    if how == "se2":
        est.align(ref, correct_scale=False, n=-1 if n is None else n)
    elif how == "origin":
        est.align_origin(ref)
    ape = evo_metrics.APE(evo_metrics.PoseRelation.translation_part)
    ape.process_data((ref, est))
    return float(ape.get_statistic(evo_metrics.StatisticsType.rmse)), int(ref.num_poses)


@pytest.mark.parametrize(
    ("align", "evo_how", "n"),
    [("se2", "se2", None), ("origin", "origin", None), ("first:20", "se2", 20), ("none", "none", None)],
)
def test_ate_of_a_file_pair_equals_evo_ape(files: tuple[Path, Path], align: str, evo_how: str, n: int | None) -> None:
    est, ref = files
    record, _ = evaluate_pair(est, ref, time_offset_s=0.3, align=align)
    expected, pairs = _evo_ape(est, ref, 0.3, evo_how, n)
    assert record.ate is not None
    assert record.ate.n == pairs == 295
    assert record.ate.rmse_m == pytest.approx(expected, abs=1e-9)
    source = record.trajectory
    assert source is not None
    assert (source.reference_without_pose, source.reference_poses, source.time_offset_s) == (5, 300, 0.3)
    assert source.alignment == align
    assert record.ate.alignment_transform.n_to_align == n


def test_the_time_offset_decides_what_is_matched(files: tuple[Path, Path]) -> None:
    est, ref = files
    with pytest.raises(Albot1Error, match=r"none of its 295 poses .* lies within 0.01 s"):
        evaluate_pair(est, ref, time_offset_s=0.05)


def test_a_wider_max_dt_is_recorded(files: tuple[Path, Path]) -> None:
    est, ref = files
    record, _ = evaluate_pair(est, ref, time_offset_s=0.3, max_dt_s=0.5)
    assert record.trajectory is not None and record.trajectory.max_dt_s == 0.5


@pytest.mark.parametrize(
    ("text", "expected"),
    [("se2", ("rigid", None)), ("origin", ("first", None)), ("first:7", ("rigid", 7)), ("NONE", ("none", None))],
)
def test_alignment_choices(text: str, expected: tuple[str, int | None]) -> None:
    assert parse_alignment(text) == expected


@pytest.mark.parametrize("text", ["first:0", "first:", "first:-1", "umeyama", "", "first:1e3", "first:\uff17"])
def test_bad_alignment_choices_are_one_line(text: str) -> None:
    with pytest.raises(Albot1Error, match=r"--align .* expected se2 \| origin \| first:N \| none"):
        parse_alignment(text)


def test_first_n_beyond_the_pairs_and_bad_offsets(files: tuple[Path, Path]) -> None:
    est, ref = files
    with pytest.raises(Albot1Error, match=r"first:1000: only 295 pose pairs"):
        evaluate_pair(est, ref, time_offset_s=0.3, align="first:1000")
    for offset in (float("nan"), float("inf"), 1e300):
        with pytest.raises(Albot1Error, match="--time-offset"):
            evaluate_pair(est, ref, time_offset_s=offset)


def test_kitti_pairs_match_by_order_and_refuse_an_offset(tmp_path: Path) -> None:
    row = "1 0 0 {x} 0 1 0 {y} 0 0 1 0\n"
    (tmp_path / "a.kitti").write_text("".join(row.format(x=i, y=0) for i in range(4)))
    (tmp_path / "b.kitti").write_text("".join(row.format(x=i, y=1) for i in range(4)))
    record, _ = evaluate_pair(tmp_path / "a.kitti", tmp_path / "b.kitti", align="none")
    assert record.ate is not None and record.ate.rmse_m == pytest.approx(1.0)
    with pytest.raises(Albot1Error, match="--time-offset needs timestamps"):
        evaluate_pair(tmp_path / "a.kitti", tmp_path / "b.kitti", time_offset_s=1.0)
    (tmp_path / "c.kitti").write_text(row.format(x=0, y=0))
    with pytest.raises(Albot1Error, match=r"a.kitti: 4 poses, .*c.kitti: 1 poses"):
        evaluate_pair(tmp_path / "a.kitti", tmp_path / "c.kitti")


def test_metrics_that_need_what_files_lack_say_why(files: tuple[Path, Path]) -> None:
    est, ref = files
    record, _ = evaluate_pair(est, ref, time_offset_s=0.3)
    assert record.rpe is not None
    assert record.relations is None and "no relations" in (record.reason("relations") or "")
    assert record.map_shape is None


def test_written_with_nine_decimals_too(tmp_path: Path) -> None:
    t = np.arange(50) * 0.1
    poses = np.column_stack([t, np.sin(t), t / 10])
    write_tum(tmp_path / "a.tum", t, poses)
    write_tum(tmp_path / "b.tum", t, poses)
    record, _ = evaluate_pair(tmp_path / "a.tum", tmp_path / "b.tum", align="none")
    assert record.ate is not None and record.ate.rmse_m == 0.0
    assert record.trajectory is not None and record.trajectory.reference_without_pose == 0


def test_align_and_time_offset_apply_to_dataset_scoring_too(tmp_path: Path) -> None:
    from albot1.data.open import open_sequence
    from albot1.runs.evaluate import evaluate_trajectory

    world = "synthetic-corridor[:60]"
    arrays = open_sequence(world).arrays
    assert arrays.reference is not None
    shifted = arrays.reference + [0.5, -0.25, 0.0]
    write_tum(tmp_path / "est.tum", arrays.timestamps[4:] - 2.0, shifted[4:])
    record, _ = evaluate_trajectory(tmp_path / "est.tum", world, time_offset_s=2.0, align="none")
    assert record.ate is not None and record.ate.alignment == "none"
    assert record.ate.rmse_m == pytest.approx(np.hypot(0.5, 0.25), abs=1e-8)
    source = record.trajectory
    assert source is not None
    assert (source.reference_without_pose, source.time_offset_s, source.alignment) == (4, 2.0, "none")
    record, _ = evaluate_trajectory(tmp_path / "est.tum", world, time_offset_s=2.0, align="origin")
    assert record.ate is not None and record.ate.rmse_m == pytest.approx(0.0, abs=1e-8)


@pytest.mark.parametrize("align", [None, "origin", "se2"])
def test_files_listed_out_of_time_order_score_as_in_order(files: tuple[Path, Path], align: str | None) -> None:
    """A path is a path in time: the pairs are put in time order whatever order the lines are in (found by an
    adversarial test: a shuffled reference scored 2.3 m of RPE for a path with 0.1 m, and another ATE with
    ``origin``)."""
    est, ref = files
    rng = np.random.default_rng(1)
    for path in (est, ref):
        lines = path.read_text().splitlines()
        shuffled = path.with_name("shuffled-" + path.name)
        shuffled.write_text("\n".join(lines[i] for i in rng.permutation(len(lines))) + "\n")
    kept, _ = evaluate_pair(est, ref, time_offset_s=0.3, align=align)
    mixed, _ = evaluate_pair(
        est.with_name("shuffled-est.tum"), ref.with_name("shuffled-gt.tum"), time_offset_s=0.3, align=align
    )
    assert kept.ate is not None and kept.rpe is not None
    assert (mixed.ate, mixed.rpe, mixed.drift, mixed.loop_gap) == (kept.ate, kept.rpe, kept.drift, kept.loop_gap)
