"""`albot1 run ... --json` and `albot1 evaluate RUN_DIR [--json]`: what they print is the records' contract."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.cli.evaluate import MAX_DT_HELP
from albot1.metrics.measures.map_shape import MapShapeBlock
from albot1.metrics.record import MetricsRecord
from albot1.metrics.registry import metric_registry
from albot1.records import Timing, parse_record, read_record
from albot1.runs.external import MAX_DT_S
from albot1.runs.folder import read_result

METRIC_NAMES = metric_registry().names

runner = CliRunner()


def invoke(*args: str) -> str:
    result = runner.invoke(app, list(args), catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.stdout


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One odometry run on the first 120 scans of the synthetic corridor (reference poses, reopenable)."""
    out = tmp_path_factory.mktemp("runs")
    summary = json.loads(invoke("run", "odometry", "synthetic-corridor", "--limit", "120", "--out", str(out), "--json"))
    return Path(summary["run_dir"])


def test_run_json_summary_is_what_result_json_says(tmp_path: Path) -> None:
    summary = json.loads(
        invoke("run", "odometry", "synthetic-corridor", "--limit", "30", "--out", str(tmp_path), "--json")
    )
    record = read_result(summary["run_dir"])
    assert summary == {
        "run_dir": summary["run_dir"],
        "method": "odometry",
        "dataset": "synthetic-corridor[:30]",  # --limit N is the prefix NAME[:N] (issue 15: part of the run key)
        "preset": "default",
        "degradation": "none",
        "seed": 0,
        "scans": 30,
        "status": "done",
        "counters": record.counters,
        "timing": json.loads(record.timing.model_dump_json()),
        "held_in": False,  # odometry is tuned on nothing (tests/unit/cli/test_cli_held_in.py)
    }
    parse_record(Timing, summary["timing"], "stdout")
    line = invoke("run", "odometry", "synthetic-corridor", "--limit", "30", "--out", str(tmp_path)).strip()
    assert line.startswith("odometry on synthetic-corridor[:30]: 30 scans, 30 updates, ")
    assert line.endswith(f" ms/scan median -> {summary['run_dir']}")


def test_evaluate_json_validates_against_the_metrics_model_and_equals_the_file(run_dir: Path) -> None:
    printed = json.loads(invoke("evaluate", str(run_dir), "--json"))
    record = parse_record(MetricsRecord, printed, "albot1 evaluate --json")
    assert record == read_record(MetricsRecord, run_dir / "metrics.json")
    assert printed == json.loads((run_dir / "metrics.json").read_text())
    assert isinstance(record.map_shape, MapShapeBlock)  # the synthetic world reopens: the map is scored
    assert record.ate is not None and record.ate.n == 120 and record.run.scans == 120
    assert record.relations is None and record.reason("relations") == "the dataset has no ground-truth relations"


def test_evaluate_prints_one_headline_per_metric_in_file_order(run_dir: Path) -> None:
    lines = invoke("evaluate", str(run_dir)).splitlines()
    assert lines[0] == str(run_dir / "metrics.json")
    assert [line.split()[0] for line in lines[1:]] == list(METRIC_NAMES)
    by_name = {line.split()[0]: line.split(maxsplit=1)[1] for line in lines[1:]}
    record = read_record(MetricsRecord, run_dir / "metrics.json")
    assert record.ate is not None
    assert by_name["ate"] == f"rmse {record.ate.rmse_m:.3f} m, max {record.ate.max_m:.3f} m (rigid alignment)"
    assert by_name["relations"] == "null: the dataset has no ground-truth relations"
    assert by_name["updates"] == "120 updates / 120 views"


def test_the_max_dt_help_states_the_default_the_runs_layer_uses() -> None:
    # The help writes the value out (the CLI module does not import the runs layer); it must stay the same.
    assert f"default {MAX_DT_S:g}," in MAX_DT_HELP
    assert MAX_DT_HELP in runner.invoke(app, ["evaluate", "--help"], env={"COLUMNS": "400"}).stdout
