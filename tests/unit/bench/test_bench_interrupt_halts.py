"""After a Ctrl-C the grid starts no more cells: an interrupted cell halts it, and so does a forkserver lost mid-fork.

Why: Ctrl-C reaches the runner, its cells and the cells' forkserver. A cell thread whose cell ended
"interrupted" (or whose fork failed as the server died: ``EOFError`` on its pipe) took the next queued cell
before the runner's thread had cancelled it, restarted the forkserver (its preload: seconds to a minute) and ran
that cell to its end, while the runner waited for the thread before it could exit: a Ctrl-C 6-10 s into
``albot1 bench quick`` took 9-116 s to end the command (``benchmarks/stop_signals.py``).
"""

from __future__ import annotations

import concurrent.futures as cf
import json
from pathlib import Path
from typing import Any

import pytest
from test_bench_failures import make_cell, plan_of

from albot1.bench import cell_main, job, limits
from albot1.bench.grid import Cell, CellOutcome
from albot1.bench.limits import ChildExit
from albot1.bench.runner import run_grid
from albot1.bench.store import FAILED, ResultsStore


def _interrupted(cell: Cell, runs_root: Path, log_path: Path, **_: object) -> ChildExit:
    """What a cell process reports when Ctrl-C reached it: its error file says so, exit code 4."""
    (runs_root / cell.key / cell_main.ERROR_FILE).write_text(
        json.dumps({"kind": "interrupted", "type": "KeyboardInterrupt", "message": ""})
    )
    return ChildExit(cell_main.EXIT_INTERRUPTED, False, 0.5)


def test_an_interrupted_cell_halts_the_grid_so_its_thread_starts_no_other_cell(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    started: list[str] = []

    def interrupted(cell: Cell, runs_root: Path, log_path: Path, **kwargs: Any) -> ChildExit:
        started.append(cell.key)
        return _interrupted(cell, runs_root, log_path)

    monkeypatch.setattr(job, "run_limited", interrupted)
    cells = [make_cell(f"k{i}") for i in range(4)]
    with cf.ThreadPoolExecutor(max_workers=1) as pool:
        summary = run_grid(plan_of(cells), ResultsStore(tmp_path), pool)
    assert started == ["k0"]  # the one thread took no further cell
    [outcome] = summary.outcomes
    assert (outcome.kind, outcome.halts_grid) == ("interrupted", True)
    assert summary.halted is not None and summary.halted.startswith("interrupted (SIGINT, e.g. Ctrl-C)")
    assert [c.key for c in summary.not_started] == ["k1", "k2", "k3"]
    assert json.loads((tmp_path / "runs" / "k0" / FAILED).read_text())["kind"] == "interrupted"  # retried next run


def test_a_forkserver_lost_while_it_forks_the_cell_is_a_lost_pool_that_halts_not_an_executor_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    class DiesWhileForking:
        def __init__(self, *args: object, **kwargs: object) -> None:
            raise EOFError("unexpected EOF")  # multiprocessing's read of the child's pid, the server gone

    monkeypatch.setattr(limits, "launcher", lambda: "forkserver")
    monkeypatch.setattr(limits, "start_forkserver", lambda methods=None: None)
    monkeypatch.setattr(limits, "ForkserverChild", DiesWhileForking)
    outcome = job.run_cell_job(make_cell(), str(tmp_path))
    assert (outcome.status, outcome.kind, outcome.halts_grid) == ("failed", "executor", True)
    assert outcome.reason == (
        "the cell process pool was shut down: its forkserver ended (EOFError on its pipe) before it started the "
        "cell; run `albot1 bench` again to retry it"
    )


class _CtrlCAtFirstOutcome:
    """A grid view whose first ``finished`` raises KeyboardInterrupt, as the CLI's view does after a Ctrl-C."""

    def started(self, total: int, cached: int) -> None:
        pass

    def finished(self, outcome: CellOutcome) -> None:
        raise KeyboardInterrupt


def test_a_runner_stopped_by_ctrl_c_starts_no_forkserver_and_forks_no_cell_for_a_thread_past_its_check(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    servers: list[object] = []
    monkeypatch.setattr(limits, "launcher", lambda: "forkserver")
    monkeypatch.setattr(limits, "start_forkserver", servers.append)

    def fails(cell: Cell, root: str) -> CellOutcome:
        return CellOutcome.of(cell, "failed", 0.1, "x", "exception")

    try:
        with cf.ThreadPoolExecutor(max_workers=1) as pool, pytest.raises(KeyboardInterrupt):
            run_grid(
                plan_of([make_cell("k0"), make_cell("k1")]), ResultsStore(tmp_path), pool, _CtrlCAtFirstOutcome(), fails
            )
        # a cell thread that took its next cell before the runner cancelled it:
        with pytest.raises(limits.CellNotStarted):
            job.run_cell_job(make_cell("k2"), str(tmp_path))
        assert not (tmp_path / "runs" / "k2").exists()  # no folder made for a cell that never started
        with pytest.raises(limits.CellNotStarted):
            limits.run_limited(make_cell("k3"), tmp_path, tmp_path / "k3.log")
        with pytest.raises(limits.CellNotStarted):  # waiting for the lock while the server died under another fork
            limits.ForkserverChild(print, (), name="cell-k4")
        assert servers == []
    finally:
        limits.allow_launching()
    with cf.ThreadPoolExecutor(max_workers=1) as pool:  # the next grid of this process starts cells again
        summary = run_grid(plan_of([make_cell("k6")]), ResultsStore(tmp_path), pool, job=fails)
    assert [o.key for o in summary.outcomes] == ["k6"]
