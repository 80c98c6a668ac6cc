"""`albot1 bench` on a real Dask cluster under faults: a worker killed, the scheduler gone, an unwritable worker.

Each test starts a scheduler and two single-threaded workers on 127.0.0.1
(:mod:`dask_cluster`), runs the CLI against it with ``--scheduler``, breaks
the cluster while slow cells run, and then checks what the local executor
guarantees: completed cells kept, every failed cell recorded with a
one-line reason, the documented exit status (1, no traceback), and a
resume on the local executor that completes the grid with a metrics table
byte-identical to a plain local run.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from dask_cluster import Cluster, cluster_env

from albot1.bench.executors import CONNECT_TIMEOUT_ENV
from albot1.bench.store import LOG, ResultsStore

WORLD = "synthetic-office-startstop[:20]"
#: Four cells (seed 0 undegraded, seeds 0-2 degraded) of about 3 s each (20 scans, 0.15 s per scan), so that a fault
#: lands while cells run: one on each of the two workers when the fault comes, and more queued behind them. Each
#: cell on a Dask worker is a fresh process (imports and all), so every cell more costs a few CPU-seconds per grid.
SLOW = f"""
[limits]
time_s = 120
memory_mb = 1024

[grid]
degradations = ["gauss:0.1:1"]
seeds = [0, 1, 2]

[[methods]]
name = "fault"
label = "slow"
set = {{ mode = "slow", sleep_s = 0.15 }}

[[datasets]]
name = "{WORLD}"
"""

# `fault`: the test-only mapper, installed as a plugin (conftest's fault_plugin) before the cluster starts.
pytestmark = [
    pytest.mark.end_to_end,
    pytest.mark.slow,
    pytest.mark.timeout(600),
    pytest.mark.usefixtures("fault_plugin"),
]


@pytest.fixture
def suite(tmp_path: Path) -> Path:
    path = tmp_path / "slow.toml"
    path.write_text(SLOW)
    return path


@pytest.fixture
def cluster(tmp_path: Path, fault_plugin: None) -> Iterator[Cluster]:
    """The cluster's processes get the plugin's folder on their path (from this process's ``sys.path``)."""
    folder = tmp_path / "cluster"
    folder.mkdir()
    # Any cell whose worker dies is lost at once (KilledWorker), rather than retried on another worker.
    running = Cluster(folder, cluster_env(DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES="0"))
    try:
        yield running
    finally:
        running.close()


def bench_command(suite: Path, results: Path, *options: str) -> list[str]:
    command = [sys.executable, "-c", "from albot1.cli.app import main; main()", "bench", str(suite)]
    return [*command, "-j", "2", "--results", str(results), "--no-progress", *options]


def start_bench(command: list[str], cwd: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(
        command, env=cluster_env(), cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def wait_for_running_cells(runs: Path, count: int, runner: subprocess.Popen[str]) -> None:
    """Wait until ``count`` cells have started (their log exists) and run a moment."""
    deadline = time.monotonic() + 240
    while len(list(runs.glob(f"*/{LOG}"))) < count:
        assert runner.poll() is None, runner.communicate()
        assert time.monotonic() < deadline, "the cells did not start on the cluster"
        time.sleep(0.1)
    time.sleep(1.0)


#: The metrics tables of a plain local run of SLOW, by file name: the same for every test (they depend on SLOW
#: only), so each worker process runs that grid once, in the first test that needs it, not once per test.
_LOCAL_TABLES: dict[str, bytes] = {}


def build_report(results: Path, out: Path, *, plots: bool) -> None:
    """:func:`albot1.report.index.build_report`, imported when a test runs (at collection it costs ~0.6 s)."""
    from albot1.report.index import build_report as build

    build(results, out, plots=plots)


def local_tables(suite: Path, tmp_path: Path) -> dict[str, bytes]:
    """``metrics.csv`` and ``metrics.md`` of SLOW run on the local executor from scratch (computed once)."""
    if not _LOCAL_TABLES:
        reference = subprocess.run(
            bench_command(suite, tmp_path / "reference"),
            env=cluster_env(),
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert reference.returncode == 0, reference.stderr
        build_report(tmp_path / "reference" / "slow", tmp_path / "report-local", plots=False)
        _LOCAL_TABLES.update({name: (tmp_path / "report-local" / name).read_bytes() for name in TABLES})
    return _LOCAL_TABLES


TABLES = ("metrics.csv", "metrics.md")


def resume_locally_and_compare(suite: Path, tmp_path: Path, results: Path) -> None:
    """Resume the grid on the local executor; its metrics table equals a local run's, byte for byte."""
    resumed = subprocess.run(
        bench_command(suite, results), env=cluster_env(), cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert resumed.returncode == 0, resumed.stderr
    build_report(results / "slow", tmp_path / "report-resumed", plots=False)
    local = local_tables(suite, tmp_path)
    for name in TABLES:
        assert (tmp_path / "report-resumed" / name).read_bytes() == local[name]


def check_recorded(store: ResultsStore, err: str) -> list[str]:
    """Every cell is complete or has a FAILED.json whose reason the CLI printed; returns the reasons."""
    reasons = []
    for cell in store.read_plan().cells:
        if store.is_complete(cell.key):
            continue
        failure = store.failure(cell.key)
        if failure is None:
            continue  # not started: the runner halted before it
        assert "Traceback" not in failure.reason and "\n" not in failure.reason
        reasons.append(failure.reason)
    assert "Traceback" not in err
    return reasons


def test_a_worker_killed_mid_cell_is_recorded_and_the_grid_resumes_locally(
    suite: Path, cluster: Cluster, tmp_path: Path
) -> None:
    cluster.start_scheduler()
    first, _ = cluster.start_worker(), cluster.start_worker()
    cluster.wait_for_workers(2)
    results = tmp_path / "results"
    runner = start_bench(bench_command(suite, results, "--scheduler", cluster.address), tmp_path)
    try:
        wait_for_running_cells(results / "slow" / "runs", 2, runner)
        first.send_signal(signal.SIGKILL)
        out, err = runner.communicate(timeout=300)
    finally:
        runner.kill()
    assert runner.returncode == 1, err
    store = ResultsStore(results / "slow")
    reasons = check_recorded(store, err)
    assert reasons, err
    assert all("Dask worker" in r and "died while it ran the cell" in r for r in reasons), reasons
    done = [c for c in store.read_plan().cells if store.is_complete(c.key)]
    assert done, "the surviving worker completed no cell"
    stamps = {c.key: (store.run_dir(c.key) / "DONE").stat().st_mtime_ns for c in done}
    resume_locally_and_compare(suite, tmp_path, results)
    assert stamps == {c.key: (store.run_dir(c.key) / "DONE").stat().st_mtime_ns for c in done}


def test_the_scheduler_lost_halts_the_runner_naming_it_and_a_restart_serves_again(
    suite: Path, cluster: Cluster, tmp_path: Path
) -> None:
    address = cluster.start_scheduler()
    # A short death timeout: the workers stop this long after their scheduler is gone (waited for below).
    cluster.start_worker(death_timeout_s=10), cluster.start_worker(death_timeout_s=10)
    cluster.wait_for_workers(2)
    results = tmp_path / "results"
    runner = start_bench(bench_command(suite, results, "--scheduler", address), tmp_path)
    try:
        wait_for_running_cells(results / "slow" / "runs", 2, runner)
        cluster.kill_scheduler()
        out, err = runner.communicate(timeout=300)
    finally:
        runner.kill()
    assert runner.returncode == 1, err
    assert f"the Dask scheduler at {address}" in err, err
    halted = [line for line in err.splitlines() if line.startswith("halted: ")]
    assert len(halted) == 1 and "run the same command again to resume" in halted[0], err
    store = ResultsStore(results / "slow")
    check_recorded(store, err)
    # The plain local run compared with below (once per test process) runs now, while the workers wait out their
    # death timeout, instead of after it: the same run and the same comparison, the two waits overlapped.
    local_tables(suite, tmp_path)
    for worker in cluster.workers:  # workers without their scheduler stop (death timeout) and stop their cells
        worker.wait(timeout=120)
    # The scheduler restarted at the same address, with fresh workers: the same command resumes on it.
    cluster.workers.clear()
    cluster.start_scheduler(port=int(address.rsplit(":", 1)[1]))
    cluster.start_worker(), cluster.start_worker()
    cluster.wait_for_workers(2)
    again = subprocess.run(
        bench_command(suite, results, "--executor", "dask://" + address.removeprefix("tcp://")),
        env=cluster_env(),
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert again.returncode == 0, again.stderr
    resume_locally_and_compare(suite, tmp_path, results)


def test_a_worker_that_cannot_write_the_results_fails_its_cell_naming_the_path(
    suite: Path, cluster: Cluster, tmp_path: Path
) -> None:
    if shutil.which("unshare") is None or os.geteuid() != 0:
        pytest.skip("needs unshare and root to give one worker a read-only view of the results folder")
    results = tmp_path / "results"
    results.mkdir()
    cluster.start_scheduler()
    read_only = ["unshare", "--mount", "--propagation", "private", "sh", "-c"]
    read_only += [f'mount --bind -o ro "{results}" "{results}" && exec "$0" "$@"']
    cluster.start_worker(wrap=read_only)
    cluster.start_worker()
    cluster.wait_for_workers(2)
    runner = start_bench(bench_command(suite, results, "--scheduler", cluster.address), tmp_path)
    out, err = runner.communicate(timeout=300)
    assert runner.returncode == 1, err
    store = ResultsStore(results / "slow")
    reasons = check_recorded(store, err)
    assert reasons, err
    assert any("read-only file system" in r and str(results / "slow" / "runs") in r for r in reasons), reasons
    assert any(line.startswith("halted: ") for line in err.splitlines()), err
    resume_locally_and_compare(suite, tmp_path, results)


def test_a_worker_with_other_code_runs_no_cell_and_says_so(suite: Path, cluster: Cluster, tmp_path: Path) -> None:
    import albot1

    other = tmp_path / "other-code"
    shutil.copytree(Path(albot1.__file__).parent, other / "albot1", ignore=shutil.ignore_patterns("__pycache__"))
    with (other / "albot1" / "versions.py").open("a") as handle:
        handle.write("\n# an edit the planning machine does not have\n")
    cluster.start_scheduler()
    env = dict(cluster.env, PYTHONPATH=os.pathsep.join([str(other), cluster.env["PYTHONPATH"]]))
    cluster.start_worker(env=env)
    cluster.wait_for_workers(1)
    results = tmp_path / "results"
    runner = start_bench(bench_command(suite, results, "--scheduler", cluster.address), tmp_path)
    out, err = runner.communicate(timeout=300)
    assert runner.returncode == 1, err
    store = ResultsStore(results / "slow")
    reasons = check_recorded(store, err)
    assert reasons and all("has albot1 code" in r and "install the same code on every worker" in r for r in reasons)
    assert not any(store.is_complete(c.key) for c in store.read_plan().cells)
    assert any(line.startswith("halted: ") for line in err.splitlines()), err


def test_a_scheduler_that_does_not_answer_is_one_line(suite: Path, tmp_path: Path) -> None:
    with socket.socket() as probe:  # a loopback port nobody listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    done = subprocess.run(
        bench_command(suite, tmp_path / "results", "--scheduler", f"127.0.0.1:{port}"),
        # nothing answers on that port, so the runner waits out its connect timeout: 2 s, not the default 10 s
        env=dict(cluster_env(), **{CONNECT_TIMEOUT_ENV: "2"}),
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 1
    assert "Traceback" not in done.stderr
    lines = [line for line in done.stderr.splitlines() if "Dask scheduler" in line]
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith(f"albot1: error: cannot reach the Dask scheduler at tcp://127.0.0.1:{port}: "), lines


def test_a_runner_interrupted_stops_its_running_cells_on_the_workers(cluster: Cluster, tmp_path: Path) -> None:
    """Ctrl-C closes the runner's client; its cells ran on in the workers' threads after it had exited.

    They wrote their folders after the results folder's lock was released, so a re-run started then (as the
    runner's last line invites) ran the same cells into the same folders at the same time. Now each worker stops
    the cell the scheduler gave up and records it as interrupted, as the local pool does.
    """
    suite = tmp_path / "hang.toml"
    suite.write_text(SLOW.replace('label = "slow"\nset = { mode = "slow", sleep_s = 0.15 }', 'set = { mode = "hang" }'))
    cluster.start_scheduler()
    for _ in range(2):
        cluster.start_worker()
    cluster.wait_for_workers(2)
    results = tmp_path / "results"
    runner = start_bench(bench_command(suite, results, "--scheduler", cluster.address), tmp_path)
    try:
        wait_for_running_cells(results / "hang" / "runs", 2, runner)
        runner.send_signal(signal.SIGINT)  # the runner alone: the workers are no children of it
        _, err = runner.communicate(timeout=120)
    finally:
        runner.kill()
    assert runner.returncode == 130, err
    store = ResultsStore(results / "hang")
    started = [c for c in store.read_plan().cells if (store.run_dir(c.key) / LOG).exists()]
    deadline = time.monotonic() + 30
    while any(store.failure(c.key) is None for c in started) and time.monotonic() < deadline:
        time.sleep(0.2)
    failures = [store.failure(c.key) for c in started]
    assert len(started) >= 2 and all(f is not None and f.kind == "interrupted" for f in failures), failures
    assert all("the runner gave the cell up" in f.reason for f in failures if f is not None)
