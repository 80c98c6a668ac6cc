"""End to end: `albot1 run odometry` on a synthetic world, then `albot1 evaluate RUN_DIR --json`."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from albot1.cli.app import app, main
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata
from albot1.data.transforms import head
from albot1.geometry import se2
from albot1.metrics.measures.loop_gap import ClosedRouteGapBlock
from albot1.metrics.registry import metric_registry
from albot1.records import dump_record
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

runner = CliRunner()


def cli(*args: str) -> dict:
    result = runner.invoke(app, list(args), catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_run_then_evaluate_a_synthetic_world(tmp_path: Path) -> None:
    run = cli("run", "odometry", "synthetic-office-loop", "--limit", "300", "--out", str(tmp_path), "--json")
    run_dir = Path(run["run_dir"])
    metrics = cli("evaluate", str(run_dir), "--json")
    assert json.loads((run_dir / "metrics.json").read_text()) == metrics
    for key in metric_registry().names:
        assert key in metrics
        # Either a computed block or null with a reason, never both, never neither.
        assert (metrics[key] is None) == (f"{key}_reason" in metrics), key
    assert metrics["relations"] is None and "relations" in metrics["relations_reason"]
    assert metrics["ate"]["alignment"] == "rigid" and metrics["ate"]["n"] == 300
    assert metrics["ate"]["rmse_m"] >= 0 and metrics["ate"]["max_m"] >= metrics["ate"]["mean_m"]
    assert metrics["updates"]["views"] == 300
    assert metrics["cost"]["scans"] == 300
    shape = metrics["map_shape"]
    # Odometry drifts but over 300 scans the projected scans still mostly land on the walls.
    assert 0.5 < shape["precision"] <= 1.0 and 0.5 < shape["coverage"] <= 1.0


def test_an_estimate_equal_to_the_reference_scores_zero(tmp_path: Path) -> None:
    n = 120
    steps = np.tile([[0.25, 0.0, np.radians(3.0)]], (n - 1, 1))  # a circle of about 4.8 m radius
    ref = se2.integrate_steps([2.0, 1.0, 0.5], steps)
    angles = np.linspace(-np.pi / 2, np.pi / 2, 31)
    frames = [Frame(i, Scan(np.full(31, 2.0), angles, i * 1.0, 8.0), ref[i], ref[i]) for i in range(n)]
    result = run_method("odometry", Sequence.from_frames("circle", frames), dataset_name="circle-in-memory")
    run_dir = write_run(result, tmp_path)
    metrics = dump_record(evaluate_run(run_dir))  # the metrics.json object
    assert metrics["ate"]["rmse_m"] == pytest.approx(0.0, abs=1e-6)
    assert metrics["rpe"]["translation_m"]["max"] == pytest.approx(0.0, abs=1e-6)
    assert metrics["orientation"]["bearing_abs_error_max_deg"] == pytest.approx(0.0, abs=1e-4)
    assert metrics["loop_gap"]["route"]["gap_m"] == pytest.approx(0.0, abs=1e-6)
    assert metrics["loop_gap"]["pairs"] > 0  # the circle (30 m round) is driven about 1.2 times, 1 s per scan
    assert metrics["loop_gap"]["translation_m"]["max"] == pytest.approx(0.0, abs=1e-6)
    # An in-memory sequence cannot be reopened: no reference map, and the reason says so.
    assert metrics["map_shape"] is None
    assert "circle-in-memory" in metrics["map_shape_reason"]


def test_without_reference_metrics_are_null_with_reasons(tmp_path: Path) -> None:
    n = 60
    poses = np.column_stack([np.arange(n) * 0.2, np.zeros(n), np.zeros(n)])
    angles = np.linspace(-np.pi / 2, np.pi / 2, 31)
    frames = [Frame(i, Scan(np.full(31, 2.0), angles, 10.0 + i * 0.5, 8.0), poses[i], None) for i in range(n)]
    result = run_method("odometry", Sequence.from_frames("in-memory", frames), dataset_name="in-memory-test")
    run_dir = write_run(result, tmp_path)
    metrics = cli("evaluate", str(run_dir), "--json")
    for key in ("ate", "rpe", "orientation", "map_shape", "loop_gap", "relations"):
        assert metrics[key] is None, key
    assert metrics["ate_reason"] == "the dataset has no reference poses"
    assert "not known to be closed" in metrics["loop_gap_reason"]
    assert metrics["updates"]["updates_per_view"] == pytest.approx(1.0)
    assert metrics["cost"]["scans"] == n


def test_evaluate_on_a_folder_that_is_not_a_run_fails_with_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr("sys.argv", ["albot1", "evaluate", str(tmp_path)])
    with pytest.raises(SystemExit) as stop:
        main()
    assert stop.value.code == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("albot1: error: ") and "not a run folder" in err and "\n" not in err


def test_a_declared_closed_route_gets_its_end_to_start_gap_without_reference(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    n = 41
    steps = np.tile([[np.pi / 2, 0.0, np.radians(9.0)]], (n - 1, 1))  # a full circle of 40 steps
    truth = se2.integrate_steps(np.zeros(3), steps)
    odometry = se2.integrate_steps(np.zeros(3), steps * [1.0, 1.0, 1.01])  # turns over-reported by 1 %
    angles = np.linspace(-np.pi / 2, np.pi / 2, 31)
    frames = [Frame(i, Scan(np.full(31, 2.0), angles, float(i), 8.0), odometry[i], None) for i in range(n)]
    closed = Sequence.from_frames("ring", frames, metadata=SequenceMetadata(extra={"closed_loop": True}))
    run_dir = write_run(run_method("odometry", closed, dataset_name="ring"), tmp_path)
    monkeypatch.setattr("albot1.runs.evaluate.open_as_run", lambda ref, *_, **__: closed)
    block = evaluate_run(run_dir).loop_gap
    assert isinstance(block, ClosedRouteGapBlock)
    assert np.allclose(truth[-1, :2], 0.0, atol=1e-9)
    assert block.route.gap_m == pytest.approx(np.hypot(*odometry[-1, :2]))
    assert block.route.gap_m > 0.5
    assert block.pairs is None and block.pairs_reason == "the dataset has no reference poses"
    # A prefix of the same route does not end at its start: no gap without a reference.
    prefix = write_run(run_method("odometry", head(closed, 30), dataset_name="ring"), tmp_path / "p")
    record = evaluate_run(prefix)
    assert record.loop_gap is None and "not known to be closed" in str(record.loop_gap_reason)
