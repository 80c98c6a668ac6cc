"""A stored metrics.json with an impossible value (negative error, NaN) is refused in one line naming file and field.

A hand edit (``"rmse_m": -0.5``) used to be printed in the report's tables as if measured.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from albot1.bench.grid import Cell, GridPlan
from albot1.bench.store import ResultsStore
from albot1.data.open import open_sequence
from albot1.metrics.record import MetricsRecord
from albot1.records import RecordError, read_record
from albot1.report.collect import collect
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import METRICS_FILE, RESULT_FILE, write_run

NEGATIVE = "expected a number >= 0 (an error, a distance or a time is never negative)"
NOT_FINITE = "expected a finite number (a record's writer stores an undefined number as null)"


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A results store of one completed cell (an odometry run of a synthetic world, evaluated)."""
    store = ResultsStore(tmp_path_factory.mktemp("results") / "t")
    store.runs.mkdir(parents=True)
    dataset = "synthetic-office-startstop[:20]"
    run_dir = write_run(run_method("odometry", open_sequence(dataset), dataset_name=dataset), store.runs)
    evaluate_run(run_dir)
    cell = Cell("t", dataset, dataset, "odometry", "odometry", "default", "none", 0, run_dir.name, "v", 60.0, 1000.0)
    store.write_plan(GridPlan("t", None, "", [cell], [], [], {}, [0], ["none"], {}))
    return store.root


def _edited(store: Path, name: str, edit: str, value: str) -> Path:
    """The one run folder's ``name`` with the JSON value at the dotted path ``edit`` replaced by ``value`` text."""
    path = next((store / "runs").iterdir()) / name
    data = json.loads(path.read_text())
    *parents, last = edit.split(".")
    node = data
    for key in parents:
        node = node[key]
    node[last] = "@@"
    path.write_text(json.dumps(data, indent=2).replace('"@@"', value))
    return path


@pytest.fixture
def pristine(store: Path) -> Path:
    """``store`` with its run files restored after the test."""
    run_dir = next((store / "runs").iterdir())
    saved = {name: (run_dir / name).read_text() for name in (METRICS_FILE, RESULT_FILE)}
    yield store  # type: ignore[misc]
    for name, text in saved.items():
        (run_dir / name).write_text(text)


def test_the_untouched_store_is_read(store: Path) -> None:
    records = collect(store)[1]
    assert [r.status for r in records] == ["done"]
    metrics = records[0].metrics
    assert metrics is not None and metrics.block("ate") is not None


@pytest.mark.parametrize(
    ("field", "value", "problem"),
    [
        ("ate.rmse_m", "-0.5", f"Value error, found -0.5; {NEGATIVE}"),
        ("rpe.translation_m.mean", "-1e-06", f"Value error, found -1e-06; {NEGATIVE}"),
        ("ate.rotation.max_deg", "-3", f"Value error, found -3.0; {NEGATIVE}"),
        ("map_shape.precision", "1.5", "Value error, found 1.5; expected a fraction from 0 to 1"),
        ("cost.per_scan_ms_median", "-2.0", f"Value error, found -2.0; {NEGATIVE}"),
    ],
)
def test_an_impossible_number_is_one_line_naming_the_file_and_the_field(
    pristine: Path, field: str, value: str, problem: str
) -> None:
    path = _edited(pristine, METRICS_FILE, field, value)
    with pytest.raises(RecordError) as err:
        collect(pristine)
    assert str(err.value) == f"{path}: not a valid MetricsRecord: {field}: {problem}"


@pytest.mark.parametrize("token", ["NaN", "Infinity", "-Infinity"])
@pytest.mark.parametrize("field", ["ate.rmse_m", "rpe.translation_m.mean"])
def test_a_non_finite_number_is_refused_not_read_as_null(pristine: Path, field: str, token: str) -> None:
    """``rpe.translation_m.mean`` may be null (an empty sample), but a NaN written there is a hand edit."""
    path = _edited(pristine, METRICS_FILE, field, token)
    with pytest.raises(RecordError) as err:
        read_record(MetricsRecord, path)
    assert str(err.value) == f"{path}: {field}: found {token}; {NOT_FINITE}"


def test_a_negative_time_in_result_json_is_refused(pristine: Path) -> None:
    path = _edited(pristine, RESULT_FILE, "timing.wall_s", "-4.0")
    with pytest.raises(RecordError) as err:
        collect(pristine)
    assert str(err.value) == f"{path}: not a valid ResultRecord: timing.wall_s: Value error, found -4.0; {NEGATIVE}"


def test_the_report_command_refuses_it_in_one_line(pristine: Path, tmp_path: Path) -> None:
    path = _edited(pristine, METRICS_FILE, "ate.rmse_m", "-0.5")
    out = tmp_path / "report"
    command = [sys.executable, "-c", "from albot1.cli.app import main; main()", "report", str(pristine)]
    done = subprocess.run(
        [*command, "--out", str(out), "--no-plots"], capture_output=True, text=True, timeout=300, env=dict(os.environ)
    )
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert (
        done.stderr == f"albot1: error: {path}: not a valid MetricsRecord: ate.rmse_m: Value error, found -0.5; "
        f"{NEGATIVE}\n"
    )


@pytest.mark.parametrize(
    ("field", "value", "problem"),
    [
        ("ate.rmse_m", "true", "Input should be a valid number"),
        ("ate.rmse_m", '"0.1"', "Input should be a valid number"),
        ("ate.n", "-3", "Input should be greater than or equal to 0, found -3"),
        ("ate.n", "2.0", "Input should be a valid integer, found 2.0"),
        ("rpe.translation_m.n", "-1", "Input should be greater than or equal to 0, found -1"),
    ],
)
def test_a_bool_a_string_or_a_negative_count_is_not_a_stored_number(
    pristine: Path, field: str, value: str, problem: str
) -> None:
    """``true`` was read as 1.0 m, ``"0.1"`` as 0.1 m and ``"n": -3`` as a count: each a hand edit shown as measured."""
    path = _edited(pristine, METRICS_FILE, field, value)
    with pytest.raises(RecordError) as err:
        collect(pristine)
    assert str(err.value).startswith(f"{path}: not a valid MetricsRecord: {field}: {problem}")


def test_a_truncated_metrics_json_of_a_done_run_is_named_not_reported_as_not_run(pristine: Path) -> None:
    """The cell completed (DONE); calling it "not run" blamed a stopped runner for a damaged file."""
    path = next((pristine / "runs").iterdir()) / METRICS_FILE
    path.write_text(path.read_text()[:40])
    with pytest.raises(RecordError) as err:
        collect(pristine)
    assert str(err.value).startswith(f"{path}: cannot read a MetricsRecord: ")


def test_a_run_folder_holding_another_cells_run_is_named_not_read_as_this_cells(pristine: Path) -> None:
    """A folder copied or renamed by hand: its numbers were shown under the planned cell's name."""
    path = _edited(pristine, RESULT_FILE, "key", '"0123456789abcdef"')
    with pytest.raises(RecordError) as err:
        collect(pristine)
    assert str(err.value) == (
        f"{path}: holds the run of cell '0123456789abcdef', not of {path.parent.name}, the folder's name "
        "(a run folder copied or renamed?)"
    )


def test_a_done_run_without_metrics_json_is_not_run(pristine: Path) -> None:
    """Stopped between the run and its evaluation: the bench evaluates it on its next pass."""
    path = next((pristine / "runs").iterdir()) / METRICS_FILE
    path.unlink()
    assert [r.status for r in collect(pristine)[1]] == ["not run"]
