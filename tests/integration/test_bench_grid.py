"""The grid end to end on a small synthetic world: failures isolated, limits enforced, results kept.

Every cell runs in its own child process, exactly as in `make bench`; the
failing cells come from ``bench_fault_mappers.FaultMapper`` registered by
an installed plugin (the ``fault_plugin`` fixture), so these tests depend on no other method.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from albot1.bench.executors import open_executor
from albot1.bench.grid import GridPlan
from albot1.bench.plan import plan_suite
from albot1.bench.runner import GridSummary, run_grid
from albot1.bench.store import ResultsStore
from albot1.bench.suite import load_suite
from albot1.report.index import build_report
from albot1.settings import Settings, get_settings

pytestmark = [pytest.mark.end_to_end, pytest.mark.usefixtures("fault_plugin")]

WORLD = "synthetic-office-startstop"
FAULT = ""  # the method `fault` is a plugin (the fault_plugin fixture installs its entry point)


def suite_file(tmp_path: Path, body: str, name: str = "tiny") -> Path:
    path = tmp_path / f"{name}.toml"
    path.write_text(body)
    return path


def run(
    path: Path, results: Path, jobs: int = 2, executor: str = "local", **executor_options: bool
) -> tuple[GridPlan, GridSummary, ResultsStore]:
    suite = load_suite(path)
    plan = plan_suite(suite, get_settings())
    store = ResultsStore(results / suite.name)
    store.write_plan(plan, path)
    with open_executor(executor, jobs, **executor_options) as pool:
        summary = run_grid(plan, store, pool)
    return plan, summary, store


FAILING = f"""
[limits]
time_s = 60
memory_mb = 1024

[grid]
degradations = ["gauss:0.1:1"]
seeds = [0, 1]

[[methods]]
name = "odometry"

[[methods]]
name = "fault"
label = "fault:raise"
{FAULT}
set = {{ mode = "raise", at_scan = 3 }}

[[methods]]
name = "fault"
label = "fault:hang"
{FAULT}
set = {{ mode = "hang", at_scan = 2 }}
time_s = 3

[[methods]]
name = "fault"
label = "fault:memory"
{FAULT}
set = {{ mode = "memory", at_scan = 2 }}
memory_mb = 300

[[methods]]
name = "fault"
label = "fault:crash"
{FAULT}
set = {{ mode = "crash", at_scan = 2 }}

[[datasets]]
name = "{WORLD}"
undegraded_seeds = []
"""


@pytest.mark.slow
def test_failures_are_isolated_recorded_and_reported(tmp_path: Path) -> None:
    plan, summary, store = run(suite_file(tmp_path, FAILING), tmp_path / "results")
    by_label: dict[str, set[str]] = {}
    for outcome in summary.outcomes:
        by_label.setdefault(outcome.method_label, set()).add(outcome.status)
    assert by_label["odometry"] == {"done"}
    for label in ("fault:raise", "fault:hang", "fault:memory", "fault:crash"):
        assert by_label[label] == {"failed"}, label
    kinds = {o.method_label: (o.kind, o.reason) for o in summary.failures}
    assert kinds["fault:raise"][0] == "exception" and "injected fault at scan 3" in kinds["fault:raise"][1]
    assert kinds["fault:hang"][0] == "timeout" and "3 s" in kinds["fault:hang"][1]
    assert kinds["fault:memory"][0] == "memory" and "300 MB" in kinds["fault:memory"][1]
    assert kinds["fault:crash"][0] == "crash" and "SIGSEGV" in kinds["fault:crash"][1]

    raised = next(c for c in plan.cells if c.method_label == "fault:raise")
    failed = json.loads((store.run_dir(raised.key) / "FAILED.json").read_text())
    assert failed["kind"] == "exception" and failed["description"]["seed"] in (0, 1)
    assert "Traceback" in (store.run_dir(raised.key) / failed["log"]).read_text()

    index = build_report(store.root, tmp_path / "report", plots=False)
    text = index.read_text()
    assert "injected fault at scan 3" in text and "time limit exceeded" in text
    assert "| odometry | gauss:0.1:1 | 2 |" in (tmp_path / "report" / "metrics.md").read_text()


TWO_ODOMETRY = f"""
[grid]
degradations = ["gauss:0.1:1"]
seeds = [0, 1]

[[methods]]
name = "odometry"

[[datasets]]
name = "{WORLD}"
"""


@pytest.mark.slow
def test_rerun_keeps_completed_cells_and_same_seeds_give_identical_tables(tmp_path: Path) -> None:
    path = suite_file(tmp_path, TWO_ODOMETRY)
    plan, first, store = run(path, tmp_path / "a")
    assert first.counts["done"] == 3 and not first.failures
    done_stamps = {c.key: (store.run_dir(c.key) / "DONE").stat().st_mtime_ns for c in plan.cells}
    _, again, _ = run(path, tmp_path / "a")
    assert again.counts["cached"] == 3 and again.counts["done"] == 0
    assert done_stamps == {c.key: (store.run_dir(c.key) / "DONE").stat().st_mtime_ns for c in plan.cells}

    _, other, other_store = run(path, tmp_path / "b", jobs=1)
    assert other.counts["done"] == 3
    build_report(store.root, tmp_path / "ra")
    # the second report is compared by its tables only, which the plots do not change (build_report writes them
    # apart from the figures): drawing its figures too would double the test's time for nothing it checks
    build_report(other_store.root, tmp_path / "rb", plots=False)
    for name in ("metrics.csv", "metrics.md", "cells.csv"):
        assert (tmp_path / "ra" / name).read_bytes() == (tmp_path / "rb" / name).read_bytes(), name
    readme = (tmp_path / "ra" / "README.md").read_text()
    assert "No cell failed." in readme and "cpu" in readme.lower()
    assert (tmp_path / "ra" / "plots" / f"{WORLD}-maps.png").is_file()
    assert (tmp_path / "ra" / "plots" / f"{WORLD}-robustness-ate.png").is_file()


@pytest.mark.slow
def test_dask_executor_runs_the_same_code_path(tmp_path: Path) -> None:
    plan, summary, store = run(
        suite_file(tmp_path, TWO_ODOMETRY), tmp_path / "results", jobs=1, executor="dask", dask_processes=False
    )
    assert summary.counts["done"] == 3
    assert all(store.is_complete(c.key) for c in plan.cells)


SLOW = f"""
[grid]
degradations = ["gauss:0.1:1"]
seeds = [0, 1, 2, 3, 4, 5]

[[methods]]
name = "fault"
label = "slow"
{FAULT}
set = {{ mode = "slow", sleep_s = 0.01 }}

[[datasets]]
name = "{WORLD}"
"""


@pytest.mark.slow
def test_sigkill_halfway_then_rerun_finishes_without_recomputing(tmp_path: Path) -> None:
    path = suite_file(tmp_path, SLOW, name="slow")
    results = tmp_path / "results"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(__file__).parent), *sys.path]))
    command = [
        sys.executable,
        "-c",
        "from albot1.cli.app import main; main()",
        "bench",
        str(path),
        "-j",
        "2",
        "--results",
        str(results),
        "--no-progress",
    ]
    runs = results / "slow" / "runs"
    store = ResultsStore(results / "slow")

    def complete() -> dict[str, int]:
        """key -> mtime of metrics.json, for the cells the store counts as complete."""
        return {
            p.name: (p / "metrics.json").stat().st_mtime_ns
            for p in (runs.iterdir() if runs.is_dir() else [])
            if store.is_complete(p.name)
        }

    runner = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not complete():
        time.sleep(0.05)
    runner.send_signal(signal.SIGKILL)
    runner.wait()
    time.sleep(0.2)  # let a cell that was writing its last file at the kill finish that rename
    first = complete()
    assert first, "no cell completed before the kill"
    plan = store.read_plan()
    assert len(first) < len(plan.cells), "the runner finished before it could be killed halfway"

    time.sleep(1.0)  # orphaned cells, if any survived the runner, would finish by now
    assert complete() == first, "cell processes outlived the killed runner"

    rerun = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    assert store.read_plan().machine["code_version"] == plan.machine["code_version"], "sources edited during the test"
    after = complete()
    assert set(after) == {c.key for c in plan.cells}
    assert {k: after[k] for k in first} == first  # completed cells were not recomputed
    for cell in plan.cells:
        json.loads((runs / cell.key / "result.json").read_text())
        assert not (runs / cell.key / "FAILED.json").exists()
    assert f"{len(first)} of {len(plan.cells)} cells already complete" in rerun.stderr, rerun.stdout + rerun.stderr


@pytest.mark.slow
def test_fresh_machine_skips_absent_datasets_and_says_how_to_fetch_them(tmp_path: Path) -> None:
    path = suite_file(
        tmp_path,
        f"""
[[methods]]
name = "odometry"

[[datasets]]
name = "{WORLD}"

[[datasets]]
name = "aces"
""",
    )
    settings = Settings(data_dir=None, cache_dir=tmp_path / "empty-cache")
    plan = plan_suite(load_suite(path), settings)
    assert [s.name for s in plan.skipped_datasets] == ["aces"]
    assert plan.skipped_datasets[0].hint == "albot1 datasets fetch aces"
    assert {c.dataset for c in plan.cells} == {WORLD}
    store = ResultsStore(tmp_path / "results" / "tiny")
    store.write_plan(plan, path)
    with open_executor("local", 1) as pool:
        summary = run_grid(plan, store, pool)
    assert summary.counts["done"] == 1
    text = build_report(store.root, tmp_path / "report", plots=False).read_text()
    assert "`aces`: not downloaded" in text and "fetch it with `albot1 datasets fetch aces`" in text
    assert "Cells: 1 planned, 1 complete, 0 failed, 0 not run." in text


ENDING = f"""
[[methods]]
name = "odometry"

[[methods]]
name = "fault"
label = "fault:exit"
set = {{ mode = "exit", at_scan = 2 }}

[[methods]]
name = "fault"
label = "fault:os-exit"
set = {{ mode = "os-exit", at_scan = 2 }}

[[methods]]
name = "fault"
label = "fault:interrupt"
set = {{ mode = "interrupt", at_scan = 2 }}

[[datasets]]
name = "{WORLD}[:6]"
"""


def test_a_method_ending_its_cell_process_is_a_failed_cell_with_its_reason(tmp_path: Path) -> None:
    """sys.exit(0) in a method once read as 'finished but left no complete run', a KeyboardInterrupt it raised as
    Ctrl-C; the rest of the grid completes."""
    plan, summary, store = run(suite_file(tmp_path, ENDING, name="ending"), tmp_path / "results", jobs=1)
    assert {o.method_label: o.status for o in summary.outcomes} == {
        "odometry": "done",
        "fault:exit": "failed",
        "fault:os-exit": "failed",
        "fault:interrupt": "failed",
    }
    reasons = {o.method_label: (o.kind, o.reason) for o in summary.failures}
    assert reasons["fault:exit"] == (
        "exception",
        f"PluginMethodError: fault on {WORLD}[:6] failed at scan 2: it raised SystemExit(0) (sys.exit); expected "
        "it to return, or to raise an exception for a failure (a method may not end the process)",
    )
    assert reasons["fault:os-exit"][0] == "exception" and "a method calling os._exit(0)?" in reasons["fault:os-exit"][1]
    assert reasons["fault:interrupt"] == (  # a KeyboardInterrupt the method raised is no Ctrl-C
        "exception",
        "KeyboardInterrupt: raised in the cell without a Ctrl-C (no SIGINT reached it): by the method?",
    )
    for cell in plan.cells:
        failed = store.run_dir(cell.key) / "FAILED.json"
        assert failed.exists() == cell.method_label.startswith("fault"), cell.method_label
