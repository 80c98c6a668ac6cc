"""Scoring an external trajectory: the same numbers as the run folder's evaluation, poses matched by time or order."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.data.model import Frame, Relations, Scan, Sequence
from albot1.data.trajectory import read_tum, write_tum
from albot1.geometry import se2
from albot1.metrics.record import MetricsRecord
from albot1.metrics.registry import metric_registry
from albot1.runs.errors import RunError
from albot1.runs.evaluate import evaluate_run, evaluate_trajectory
from albot1.runs.evo_results import write_evo_results
from albot1.runs.execute import run_method
from albot1.runs.external import NO_MAP, match_by_time
from albot1.runs.folder import write_run

METRIC_NAMES = metric_registry().names

N = 130
SCORED_ALIKE = ("ate", "ate_windows", "rpe", "drift", "loop_gap", "orientation", "relations")


def _circle() -> Sequence:
    """1 m and 3 deg per scan (a 120 m circle, driven 1.1 times), turns over-reported by 1 %, 3 relations."""
    steps = np.tile([[1.0, 0.0, np.radians(3.0)]], (N - 1, 1))
    truth = se2.integrate_steps(np.zeros(3), steps)
    odometry = se2.integrate_steps(np.zeros(3), steps * [1.0, 1.0, 1.01])
    angles = np.linspace(-np.pi / 2, np.pi / 2, 31)
    frames = [Frame(i, Scan(np.full(31, 2.0), angles, 10.0 + i, 8.0), odometry[i], truth[i]) for i in range(N)]
    stamps = 10.0 + np.array([0.0, 5.0, 40.0])
    relations = Relations(stamps, stamps + [1.0, 1.0, 80.0], se2.between(truth[[0, 5, 40]], truth[[1, 6, 120]]))
    return Sequence.from_frames("circle", frames, relations=relations)


@pytest.fixture
def dataset(monkeypatch: pytest.MonkeyPatch) -> Sequence:
    """The circle, opened by the name ``circle`` (as a catalog dataset would be)."""
    sequence = _circle()
    monkeypatch.setattr("albot1.runs.external.open_sequence", lambda ref, **_: sequence)
    return sequence


def test_a_run_folders_trajectory_scored_as_a_file_matches_its_evaluation_digit_for_digit(
    tmp_path: Path, dataset: Sequence
) -> None:
    run_dir = write_run(run_method("odometry", dataset, dataset_name="circle"), tmp_path)
    from_run = evaluate_run(run_dir)
    from_file, _ = evaluate_trajectory(run_dir / "trajectory.tum", "circle", out=tmp_path / "ext.json")
    for name in SCORED_ALIKE:
        assert from_file.block(name) is not None, name
        assert from_file.block(name) == from_run.block(name), name  # every number equal, not close
    assert (from_file.map_shape, from_file.reason("map_shape")) == (None, NO_MAP)
    assert from_file.updates is None and from_file.cost is None
    source = from_file.trajectory
    assert source is not None and (source.format, source.poses, source.matched, source.unmatched) == ("tum", N, N, 0)
    assert from_file.run.seed is None and from_file.run.preset == "external" and from_file.run.method == "trajectory"
    written = json.loads((tmp_path / "ext.json").read_text())
    assert written["trajectory"]["matched"] == N and "trajectory" not in json.loads(
        (run_dir / "metrics.json").read_text()
    )


def test_poses_are_matched_to_the_nearest_scan_in_time_and_the_others_counted() -> None:
    scans = np.array([0.0, 1.0, 2.0, 3.0])
    poses = np.array([0.004, 0.996, 1.003, 2.5, 3.0, 7.0])
    matching = match_by_time(poses, scans, 0.01)
    assert matching.scan_index.tolist() == [0, 1, 3]
    assert matching.pose_index.tolist() == [0, 2, 4]  # scan 1: the pose 0.003 s away beats the one 0.004 s away
    assert (matching.unmatched, matching.duplicates) == (2, 1)  # 2.5 s and 7 s: no scan within 0.01 s


def test_a_partial_trajectory_is_scored_on_its_poses_and_says_what_it_left_out(
    tmp_path: Path, dataset: Sequence
) -> None:
    stamps, poses = dataset.timestamps, dataset.arrays.reference
    assert poses is not None
    keep = np.arange(0, N, 2)
    shifted = stamps[keep] + np.where(keep > 100, 0.5, 0.0)  # the poses after scan 100 are 0.5 s late
    write_tum(tmp_path / "half.tum", shifted, poses[keep])
    record, _ = evaluate_trajectory(tmp_path / "half.tum", "circle", label="perfect")
    source = record.trajectory
    assert source is not None and (source.poses, source.matched, source.unmatched) == (65, 51, 14)
    assert record.ate is not None and record.ate.n == 51 and record.ate.rmse_m < 1e-8
    assert record.run.method == "perfect" and record.run.scans == 51


def test_kitti_poses_are_matched_by_order_and_must_cover_every_scan(tmp_path: Path, dataset: Sequence) -> None:
    truth = dataset.arrays.reference
    assert truth is not None
    c, s = np.cos(truth[:, 2]), np.sin(truth[:, 2])
    rows = np.column_stack([c, -s, 0 * c, truth[:, 0], s, c, 0 * c, truth[:, 1], 0 * c, 0 * c, 1 + 0 * c, 0 * c])
    np.savetxt(tmp_path / "poses.txt", rows, fmt="%.12f")
    record, _ = evaluate_trajectory(tmp_path / "poses.txt", "circle")
    assert record.trajectory is not None and record.trajectory.format == "kitti" and record.trajectory.max_dt_s is None
    assert record.ate is not None and record.ate.rmse_m < 1e-8
    np.savetxt(tmp_path / "short.txt", rows[:-3], fmt="%.12f")
    with pytest.raises(RunError, match=r"127 poses without timestamps \(kitti\), but dataset 'circle' has 130 scans"):
        evaluate_trajectory(tmp_path / "short.txt", "circle")


def test_a_trajectory_far_from_the_logs_times_is_one_clear_error(tmp_path: Path, dataset: Sequence) -> None:
    write_tum(tmp_path / "t.tum", np.arange(5) + 1e6, np.zeros((5, 3)))
    with pytest.raises(RunError, match=r"none of its 5 poses .* lies within 0.01 s of a scan of 'circle'"):
        evaluate_trajectory(tmp_path / "t.tum", "circle")


def test_evo_result_files_hold_the_same_statistics_as_metrics_json(tmp_path: Path, dataset: Sequence) -> None:
    from evo.tools.file_interface import load_res_file

    run_dir = write_run(run_method("odometry", dataset, dataset_name="circle"), tmp_path / "runs")
    record, scored = evaluate_trajectory(run_dir / "trajectory.tum", "circle", label="dead reckoning")
    ape_zip, rpe_zip = write_evo_results(scored, tmp_path / "evo", prefix="dr.")
    assert (ape_zip.name, rpe_zip.name) == ("dr.ape.zip", "dr.rpe.zip")
    ape, rpe = load_res_file(ape_zip), load_res_file(rpe_zip)
    assert record.ate is not None and record.rpe is not None
    assert ape.stats["rmse"] == pytest.approx(record.ate.rmse_m, rel=1e-12)
    assert ape.stats["max"] == pytest.approx(record.ate.max_m, rel=1e-12)
    assert rpe.stats["rmse"] == pytest.approx(record.rpe.translation_m.rmse, rel=1e-12)
    assert ape.info["est_name"] == "dead reckoning" and len(ape.np_arrays["error_array"]) == N


def test_cli_scores_a_trajectory_of_a_synthetic_world_and_prints_json(tmp_path: Path) -> None:
    world = "synthetic-office-loop[:120]"
    from albot1.data.open import open_sequence

    reference = open_sequence(world).arrays
    assert reference.reference is not None
    write_tum(tmp_path / "truth.tum", reference.timestamps, reference.reference)
    done = CliRunner().invoke(
        app, ["evaluate", "--trajectory", str(tmp_path / "truth.tum"), "--dataset", world, "--json"]
    )
    assert done.exit_code == 0, done.output
    record = MetricsRecord.model_validate(json.loads(done.stdout))
    assert record.ate is not None and record.ate.rmse_m < 1e-8 and record.run.dataset == world
    assert all(record.block(n) is not None or record.reason(n) for n in METRIC_NAMES)
    both = CliRunner().invoke(app, ["evaluate", str(tmp_path), "--trajectory", str(tmp_path / "truth.tum")])
    assert both.exit_code == 2 and "not both" in both.output
    _, poses = read_tum(tmp_path / "truth.tum")
    assert len(poses) == 120
