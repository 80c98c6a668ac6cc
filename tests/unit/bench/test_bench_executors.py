"""Executors: ``--scheduler`` as an alias of ``dask://``, one-line reasons for lost jobs, cells the executor drops."""

from __future__ import annotations

import concurrent.futures as cf
import logging
import sys
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from test_bench_failures import make_cell, plan_of

from albot1.bench.errors import BenchError
from albot1.bench.executors import (
    CONNECT_TIMEOUT_ENV,
    CONNECT_TIMEOUT_S,
    _quiet_cancellations,
    connect_timeout_s,
    executor_failure,
    open_executor,
    parse_executor,
    scheduler_executor,
)
from albot1.bench.grid import Cell, CellOutcome
from albot1.bench.runner import run_grid
from albot1.bench.store import LOG, ResultsStore


@pytest.mark.parametrize("address", ["127.0.0.1:8786", "tcp://127.0.0.1:8786", "dask://127.0.0.1:8786"])
def test_scheduler_is_the_dask_url_of_its_address(address: str) -> None:
    assert scheduler_executor(address) == "dask://127.0.0.1:8786"
    assert parse_executor(scheduler_executor(address)) == ("dask", "tcp://127.0.0.1:8786")
    assert scheduler_executor(address, "dask://127.0.0.1:8786") == "dask://127.0.0.1:8786"


@pytest.mark.parametrize("address", ["", "127.0.0.1", "host:port", "host:0", "host:70000", ":8786", "a/b:1"])
def test_a_scheduler_address_without_host_and_port_is_refused(address: str) -> None:
    with pytest.raises(BenchError, match="expected HOST:PORT"):
        scheduler_executor(address)


def test_the_scheduler_connect_timeout_is_10_s_unless_the_environment_says(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(CONNECT_TIMEOUT_ENV, raising=False)
    assert connect_timeout_s() == CONNECT_TIMEOUT_S == 10.0
    monkeypatch.setenv(CONNECT_TIMEOUT_ENV, " 2.5 ")
    assert connect_timeout_s() == 2.5


@pytest.mark.parametrize("value", ["0", "-1", "soon", "nan", "inf", "1e999"])
def test_a_connect_timeout_that_is_not_a_positive_number_is_one_line(
    value: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(CONNECT_TIMEOUT_ENV, value)
    message = f"{CONNECT_TIMEOUT_ENV}={value!r}: expected a number of seconds above 0"
    with pytest.raises(BenchError) as refused:
        connect_timeout_s()
    assert str(refused.value) == message
    with pytest.raises(BenchError) as refused, open_executor("dask://127.0.0.1:1", 1):
        pass  # refused before any connection is tried
    assert str(refused.value) == message


def test_scheduler_and_another_executor_together_are_refused() -> None:
    with pytest.raises(BenchError, match="name two executors; give one of them"):
        scheduler_executor("127.0.0.1:8786", "dask")


def test_a_killed_worker_fails_its_cell_only_with_one_line() -> None:
    from distributed import KilledWorker  # here, not at collection: distributed takes ~0.4 s to import

    exc = KilledWorker("_unless_halted-1", SimpleNamespace(address="tcp://127.0.0.1:1"), allowed_failures=0)
    with cf.ThreadPoolExecutor(1) as pool:
        reason, halts = executor_failure(exc, pool)
    assert not halts and "\n" not in reason
    assert reason.startswith("the Dask worker that ran the cell died while it ran the cell")
    assert reason.endswith("run `albot1 bench` again to retry it")


def test_a_closed_connection_halts_and_other_errors_keep_their_first_line() -> None:
    class CommClosedError(OSError):
        pass

    with cf.ThreadPoolExecutor(1) as pool:
        assert executor_failure(CommClosedError("in <TCP>: Stream is closed"), pool) == (
            "the connection to the executor was lost: CommClosedError: in <TCP>: Stream is closed; "
            "run `albot1 bench` again to retry the cell",
            True,
        )
        assert executor_failure(ValueError("first\nsecond"), pool) == ("executor error: ValueError: first", False)


class DroppingExecutor(cf.Executor):
    """Runs ``started`` jobs, then cancels every other job as a Dask client cancels them when its scheduler goes."""

    def __init__(self, started: int) -> None:
        self.started = started
        self.submitted = 0

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> cf.Future[Any]:
        future: cf.Future[Any] = cf.Future()
        self.submitted += 1
        if self.submitted <= self.started:
            future.set_result(fn(*args, **kwargs))
        else:
            future.cancel()
            future.set_running_or_notify_cancel()
        return future


def test_cells_the_executor_cancels_halt_the_grid_and_are_never_dropped(tmp_path: Path) -> None:
    cells = [make_cell(f"k{i}") for i in range(4)]
    store = ResultsStore(tmp_path)
    store.prepare(cells[2])  # k2 had started when the executor lost it

    def job(cell: Cell, root: str) -> CellOutcome:
        return CellOutcome.of(cell, "done")

    summary = run_grid(plan_of(cells), store, DroppingExecutor(started=2), job=job)
    assert summary.halted == "the executor cancelled the cell (its Dask scheduler restarted?)"
    assert summary.counts["done"] == 2
    assert [o.key for o in summary.failures] == ["k2"]
    assert (
        summary.failures[0].reason
        == "the executor cancelled the cell (its Dask scheduler restarted?); the cell was running"
    )
    failure = store.failure("k2")
    assert failure is not None and failure.kind == "executor"
    assert [c.key for c in summary.not_started] == ["k3"]
    assert (store.run_dir("k2") / LOG).is_file()


def test_a_failure_the_job_could_not_record_is_recorded_by_the_runner(tmp_path: Path) -> None:
    cells = [make_cell("k0")]
    store = ResultsStore(tmp_path)

    def unwritable(cell: Cell, root: str) -> CellOutcome:
        reason = "cannot write the results: read-only file system: /r/runs/k0 [not recorded: /r/runs/k0/FAILED.json]"
        return CellOutcome.of(cell, "failed", 0.0, reason, "storage", halts_grid=True)

    with cf.ThreadPoolExecutor(1) as pool:
        summary = run_grid(plan_of(cells), store, pool, job=unwritable)
    failure = store.failure("k0")
    assert failure is not None and failure.kind == "storage"
    assert failure.reason == summary.failures[0].reason == "cannot write the results: read-only file system: /r/runs/k0"


def _callback_record(exc: BaseException) -> logging.LogRecord:
    """The record tornado logs for an exception raised in an event-loop callback."""
    try:
        raise exc
    except BaseException:
        return logging.getLogger("tornado.application").makeRecord(
            "tornado.application", logging.ERROR, __file__, 1, "Exception in callback %r", ("cb",), sys.exc_info()
        )


def test_the_runner_s_own_cancellations_never_print_a_traceback_and_other_errors_still_do(
    caplog: pytest.LogCaptureFixture,
) -> None:
    from distributed.client import FutureCancelledError

    logger = logging.getLogger("tornado.application")
    with caplog.at_level(logging.ERROR, logger="tornado.application"), _quiet_cancellations():
        logger.handle(_callback_record(FutureCancelledError("k", "halted")))
        logger.handle(_callback_record(RuntimeError("a real fault")))
    assert [record.getMessage() for record in caplog.records] == ["Exception in callback 'cb'"]
    assert caplog.records[0].exc_info is not None
    assert isinstance(caplog.records[0].exc_info[1], RuntimeError)
    assert logger.filters == []


def test_a_connection_dask_closed_prints_no_traceback_from_asyncio_or_tornado(caplog: pytest.LogCaptureFixture) -> None:
    from distributed.comm.core import CommClosedError
    from tornado.iostream import StreamClosedError

    def record(name: str, exc: BaseException) -> logging.LogRecord:
        try:
            raise exc
        except BaseException:
            return logging.getLogger(name).makeRecord(
                name, logging.ERROR, __file__, 1, "Task exception was never retrieved", (), sys.exc_info()
            )

    with caplog.at_level(logging.ERROR), _quiet_cancellations():
        for name in ("asyncio", "tornado.application"):
            logging.getLogger(name).handle(record(name, CommClosedError("in <TCP (closed)>: Stream is closed")))
            logging.getLogger(name).handle(record(name, StreamClosedError()))
            logging.getLogger(name).handle(record(name, RuntimeError(f"a real fault in {name}")))
    assert [str(r.exc_info[1]) for r in caplog.records if r.exc_info] == [
        "a real fault in asyncio",
        "a real fault in tornado.application",
    ]
    assert logging.getLogger("asyncio").filters == [] and logging.getLogger("tornado.application").filters == []


class PendingWhileRunningExecutor(cf.Executor):
    """Futures that stay pending while their job runs, as a Dask client's do; a cancelled one is never notified.

    The first job completes at once; every other job "runs" until :meth:`finish`, which sets the results the way
    ``distributed.cfexecutor`` does: on a future the runner cancelled meanwhile, ``set_result`` raises
    ``InvalidStateError`` (swallowed here, logged there) and the future stays cancelled without notification.
    """

    def __init__(self) -> None:
        self.running: list[tuple[cf.Future[Any], Callable[[], Any]]] = []

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> cf.Future[Any]:
        future: cf.Future[Any] = cf.Future()
        if not self.running and not getattr(self, "first_done", False):
            self.first_done = True
            future.set_result(fn(*args, **kwargs))
        else:
            self.running.append((future, lambda: fn(*args, **kwargs)))
        return future

    def finish(self) -> None:
        for future, call in self.running:
            try:
                future.set_result(call())
            except cf.InvalidStateError:
                pass


def test_a_halt_does_not_wait_for_a_running_cell_it_cancelled(tmp_path: Path) -> None:
    import threading

    cells = [make_cell(f"k{i}") for i in range(3)]
    store = ResultsStore(tmp_path)
    executor = PendingWhileRunningExecutor()

    def job(cell: Cell, root: str) -> CellOutcome:
        if cell.key == "k0":
            return CellOutcome.of(
                cell, "failed", 0.0, "cannot write the results: no space left", "storage", halts_grid=True
            )
        return CellOutcome.of(cell, "done")

    ended: list[Any] = []
    grid = threading.Thread(
        target=lambda: ended.append(run_grid(plan_of(cells), store, executor, job=job)), daemon=True
    )
    grid.start()
    grid.join(timeout=5)
    executor.finish()  # the "running" cells end after the runner cancelled them
    grid.join(timeout=5)
    assert ended, "the runner waited for cells it had cancelled"
    summary = ended[0]
    assert summary.halted == "cannot write the results: no space left"
    assert [c.key for c in summary.not_started] == ["k1", "k2"]


def test_two_local_dask_clusters_at_once_warn_of_no_taken_port(tmp_path: Path) -> None:
    """The scheduler's HTTP routes went to port 8787 and warned on the terminal when a second bench (or a notebook's
    cluster) held it: each local cluster now takes a free loopback port, so nothing is printed."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with open_executor("dask", 1, dask_processes=False) as first, open_executor("dask", 1, dask_processes=False):
            assert first.submit(sum, [1, 2]).result(timeout=60) == 3
    taken = [str(w.message) for w in caught if "already in use" in str(w.message)]
    assert taken == []
