"""Limits and a killed process pool with real cells: what is recorded, and that the grid resumes.

The memory limit is measured as resident memory by the supervisor, so the
real methods (numba's LLVM for albot1, gtsam, kiss-icp) load and run under
it; an address-space limit of the same size made them fail to import.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from albot1.bench.executors import open_executor
from albot1.bench.plan import plan_suite
from albot1.bench.runner import run_grid
from albot1.bench.store import ResultsStore
from albot1.bench.suite import load_suite
from albot1.settings import get_settings

pytestmark = [pytest.mark.end_to_end, pytest.mark.usefixtures("fault_plugin")]

WORLD = "synthetic-office-startstop"
METHODS = ("odometry", "albot1", "kiss-icp", "gtsam-graph")


def grid_with_memory_limit(tmp_path: Path, memory_mb: int) -> dict[str, tuple[str, str | None, str | None]]:
    """Every method on the world under ``memory_mb``: label -> (status, kind, reason)."""
    path = tmp_path / f"mem{memory_mb}.toml"
    methods = "".join(f'[[methods]]\nname = "{m}"\n' for m in METHODS)
    path.write_text(f'[limits]\nmemory_mb = {memory_mb}\ntime_s = 300\n{methods}[[datasets]]\nname = "{WORLD}"\n')
    suite = load_suite(path)
    plan = plan_suite(suite, get_settings())
    store = ResultsStore(tmp_path / "results" / suite.name)
    store.write_plan(plan, path)
    with open_executor("local", 2) as pool:
        summary = run_grid(plan, store, pool)
    return {o.method_label: (o.status, o.kind, o.reason) for o in summary.outcomes}


@pytest.mark.slow
def test_the_real_methods_run_under_a_resident_memory_limit(tmp_path: Path) -> None:
    outcomes = grid_with_memory_limit(tmp_path, 512)  # measured peaks on this world: 105-240 MB
    assert outcomes == {m: ("done", None, None) for m in METHODS}, outcomes


@pytest.mark.slow
def test_a_cell_over_its_memory_limit_is_reported_as_such_not_as_an_import_error(tmp_path: Path) -> None:
    outcomes = grid_with_memory_limit(tmp_path, 40)
    for method, (status, kind, reason) in outcomes.items():
        assert (status, kind) == ("failed", "memory"), (method, reason)
        assert reason is not None and reason.startswith("memory limit exceeded: resident memory reached")
        assert reason.endswith("over the cell's limit of 40 MB (killed)")


#: Four cells of about 3 s each (30 scans at 0.1 s): long enough that two are running when the pool is killed
#: (two more wait behind them), short enough that the resume does not wait on the whole world (106 scans).
SLOW = f"""
[grid]
degradations = ["gauss:0.1:1"]
seeds = [0, 1, 2]

[[methods]]
name = "fault"
label = "slow"
set = {{ mode = "slow", sleep_s = 0.1 }}

[[datasets]]
name = "{WORLD}[:30]"
"""


def _command_line(process: psutil.Process) -> str:
    """The process's command line, or "" for one that ended or is a zombie (short-lived helpers such as `git`
    come and go while the runner starts)."""
    try:
        return " ".join(process.cmdline())
    except (psutil.NoSuchProcess, psutil.ZombieProcess, psutil.AccessDenied):
        return ""


def _children(process: psutil.Process) -> list[psutil.Process]:
    try:
        return process.children()
    except (psutil.NoSuchProcess, psutil.ZombieProcess):
        return []


@pytest.mark.slow
def test_killing_the_cell_pool_is_named_halts_the_grid_and_a_rerun_resumes(tmp_path: Path) -> None:
    suite = tmp_path / "slow.toml"
    suite.write_text(SLOW)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(__file__).parent), *sys.path]))
    command = [sys.executable, "-c", "from albot1.cli.app import main; main()", "bench", str(suite)]
    command += ["-j", "2", "--results", str(tmp_path / "results"), "--no-progress"]
    runner = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        cells: list[psutil.Process] = []
        while time.monotonic() < deadline and len(cells) < 2:  # wait for two running cells under the forkserver
            servers = [p for p in psutil.Process(runner.pid).children() if "forkserver" in _command_line(p)]
            cells = [c for s in servers for c in _children(s)]
            time.sleep(0.1)
        assert len(servers) == 1 and len(cells) == 2, "the cells did not start"
        time.sleep(1.0)
        os.kill(servers[0].pid, signal.SIGKILL)
        out, err = runner.communicate(timeout=300)
    finally:
        runner.kill()
    assert runner.returncode == 1, err
    assert "Traceback" not in err and "exited with code 255" not in err
    failed = [line for line in err.splitlines() if line.startswith("FAILED ")]
    assert len(failed) == 2, err  # the two running cells; the other 2 of the 4 never start
    assert all("the cell process pool was shut down: its forkserver was killed by SIGKILL" in f for f in failed)
    assert any(line.startswith("halted: ") and "2 cells not started" in line for line in err.splitlines()), err
    time.sleep(0.5)
    assert not any(c.is_running() and c.status() != psutil.STATUS_ZOMBIE for c in cells), "cells outlived the pool"

    rerun = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    store = ResultsStore(tmp_path / "results" / "slow")
    assert all(store.is_complete(c.key) for c in store.read_plan().cells)
