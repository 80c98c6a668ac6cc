"""Where cells run: a local pool or Dask distributed, both as a ``concurrent.futures.Executor``.

One code path: the runner only calls ``submit`` and ``concurrent.futures.as_completed``.

``local`` (default)
    a thread pool of ``jobs`` threads; each thread supervises one cell
    process at a time (:mod:`albot1.bench.limits`), so ``-j N`` means N cell
    processes at once. Threads, not a process pool, because the supervisor
    must survive its cell being killed (a crashed ``ProcessPoolExecutor``
    worker breaks the whole pool).
``dask``
    a ``distributed.LocalCluster`` of ``jobs`` single-threaded workers,
    through ``Client.get_executor()``. Its worker processes are made
    non-daemonic so they may fork cell processes themselves.
``dask://HOST:PORT`` (or ``tcp://``)
    an existing scheduler. Its workers must have albot1 installed and see
    the results folder (and the datasets) at the same paths as this machine.
    A scheduler that does not answer within :func:`connect_timeout_s` is a
    one-line error.
"""

from __future__ import annotations

import concurrent.futures as cf
import logging
import math
import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from albot1.bench.errors import BenchError

EXECUTORS_HELP = "local | dask | dask://HOST:PORT"
#: Seconds to wait for a ``dask://`` scheduler to answer; the variable below changes it (a slow network
#: may need more, and the test of an unreachable scheduler less: the wait is the whole of that test).
CONNECT_TIMEOUT_S = 10.0
CONNECT_TIMEOUT_ENV = "ALBOT1_DASK_CONNECT_TIMEOUT"
#: Where a local Dask cluster's scheduler serves its HTTP routes: any free port, loopback only.
LOCAL_HTTP_ADDRESS = "127.0.0.1:0"


def connect_timeout_s() -> float:
    """:data:`CONNECT_TIMEOUT_S`, or ``ALBOT1_DASK_CONNECT_TIMEOUT`` when set (seconds above 0, else a BenchError)."""
    text = os.environ.get(CONNECT_TIMEOUT_ENV, "").strip()
    if not text:
        return CONNECT_TIMEOUT_S
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not (math.isfinite(seconds) and seconds > 0):
        raise BenchError(f"{CONNECT_TIMEOUT_ENV}={text!r}: expected a number of seconds above 0")
    return seconds


def parse_executor(spec: str) -> tuple[str, str | None]:
    """``local`` -> ("local", None); ``dask`` -> ("dask", None); ``dask://h:p`` -> ("dask", "tcp://h:p")."""
    text = spec.strip()
    if text in ("local", "dask"):
        return text, None
    for prefix in ("dask://", "tcp://"):
        if text.startswith(prefix) and len(text) > len(prefix):
            return "dask", "tcp://" + text[len(prefix) :]
    raise BenchError(f"executor {spec!r} not understood; expected {EXECUTORS_HELP}")


def scheduler_executor(address: str, executor: str = "local") -> str:
    """``--scheduler ADDRESS`` as the executor it abbreviates: ``HOST:PORT`` or ``tcp://HOST:PORT`` -> ``dask://HOST:PORT``.

    ``executor`` is the ``--executor`` given with it: only its default (or the same address) may be.
    """
    text = address.strip()
    host_port = text.removeprefix("tcp://").removeprefix("dask://")
    host, _, port = host_port.rpartition(":")
    if not host or "/" in host_port or not port.isdigit() or not 0 < int(port) < 65536:
        raise BenchError(f"--scheduler {address!r}: expected HOST:PORT (or tcp://HOST:PORT) of a Dask scheduler")
    spec = f"dask://{host_port}"
    if executor.strip() != "local" and parse_executor(executor) != parse_executor(spec):
        raise BenchError(f"--scheduler {address} and --executor {executor} name two executors; give one of them")
    return spec


def check_jobs(jobs: int) -> int:
    """``jobs`` when it is a usable number of parallel cells (at least one), else a BenchError."""
    if jobs < 1:
        raise BenchError(f"-j {jobs}: expected at least one parallel job")
    return jobs


@contextmanager
def open_executor(spec: str, jobs: int, *, dask_processes: bool = True) -> Iterator[cf.Executor]:
    """The executor named by ``spec`` with ``jobs`` parallel cells; shut down on exit."""
    check_jobs(jobs)
    kind, address = parse_executor(spec)
    if kind == "local":
        with cf.ThreadPoolExecutor(max_workers=jobs, thread_name_prefix="cell") as pool:
            yield pool
        return
    timeout_s = connect_timeout_s() if address is not None else None  # a bad setting fails before the imports
    import dask
    from distributed import Client, LocalCluster

    if address is not None:
        try:
            client = Client(address, timeout=timeout_s)
        except OSError as exc:
            raise BenchError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
        with _quiet_client_logs():
            try:
                yield client.get_executor(pure=False)
            finally:
                client.close()
        return
    # No dashboard; the scheduler still serves its HTTP routes (health, metrics), by default on port 8787, and
    # warns on the user's terminal when that port is taken (a second bench, a notebook's cluster): a free port of
    # the loopback interface instead, never reachable from another machine.
    with dask.config.set({"distributed.worker.daemon": False}), _children_ignore_ctrl_c():
        cluster = LocalCluster(
            n_workers=jobs,
            threads_per_worker=1,
            processes=dask_processes,
            dashboard_address=None,
            # the workers' and scheduler's warnings (a task cancelled as the cluster closes after Ctrl-C or a
            # halt) are distributed's own bookkeeping, not the grid's: the runner says what happened in one line
            silence_logs=logging.ERROR,
            scheduler_kwargs={"dashboard_address": LOCAL_HTTP_ADDRESS},
        )
    try:
        with Client(cluster) as client, _quiet_cancellations():
            yield client.get_executor(pure=False)
    finally:
        cluster.close()


@contextmanager
def _children_ignore_ctrl_c() -> Iterator[None]:
    """SIGINT ignored while the local cluster spawns its worker processes, which keep that disposition.

    Ctrl-C reaches the whole process group: the runner stops the grid (``albot1: interrupted``, exit 130) and
    closes the cluster, which ends the workers and their cells. The workers, Python processes started by
    ``exec`` with SIGINT at its default, raised KeyboardInterrupt in their event loops as well, and
    multiprocessing printed two tracebacks per worker above the runner's one line. A disposition of
    SIG_IGN survives ``exec`` (Python then installs no handler), and the cells' forkserver, which sets
    SIGINT's default action for its preload, puts the inherited one back after it. Only the main thread
    may set a handler; elsewhere nothing changes. A Ctrl-C during the start itself (a second or two) is
    ignored; a worker the nanny restarts later is spawned with the runner's handler (as before).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


@contextmanager
def _quiet_client_logs() -> Iterator[None]:
    """Keep distributed's own tracebacks (a lost scheduler, its failed reconnection) off the user's terminal.

    The runner reports what they mean as one line (:func:`executor_lost`,
    :func:`executor_failure`); the levels are restored afterwards.
    """
    loggers = [logging.getLogger(name) for name in ("distributed", "distributed.client", "distributed.core")]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL)
    try:
        with _quiet_cancellations():
            yield
    finally:
        for logger, level in zip(loggers, levels, strict=True):
            logger.setLevel(level)


class _DropCancellations(logging.Filter):
    """Drop records of the runner's own cancellations and of connections Dask closed, with their tracebacks.

    When the runner halts a grid it cancels the queued cells;
    ``distributed.cfexecutor`` then re-raises each cancellation inside a
    tornado callback, and tornado logs it with a traceback on the user's
    terminal. The cancellation is the runner's own doing and is reported as
    ``halted: ...`` with the cells not started. A connection that closed under
    a worker or scheduler the runner refused or lost (``CommClosedError``,
    tornado's ``StreamClosedError``) can reach the terminal the same way, or
    through asyncio's "Task exception was never retrieved" (seen under load:
    a worker with other code, whose refusal the runner reports as one line).
    Every other record passes.
    """

    _DROPPED = frozenset({"FutureCancelledError", "CancelledError", "CommClosedError", "StreamClosedError"})

    def filter(self, record: logging.LogRecord) -> bool:
        exc = record.exc_info[1] if record.exc_info else None
        return not (exc is not None and any(kind.__name__ in self._DROPPED for kind in type(exc).__mro__))


#: The loggers that print a traceback for a closed connection or a cancellation: tornado's callbacks, asyncio's tasks.
_CALLBACK_LOGGERS = ("tornado.application", "asyncio")


@contextmanager
def _quiet_cancellations() -> Iterator[None]:
    """:class:`_DropCancellations` on tornado's and asyncio's loggers while a Dask executor is in use."""
    loggers = [logging.getLogger(name) for name in _CALLBACK_LOGGERS]
    drop = _DropCancellations()
    for logger in loggers:
        logger.addFilter(drop)
    try:
        yield
    finally:
        for logger in loggers:
            logger.removeFilter(drop)


def _dask_client(executor: cf.Executor) -> Any:
    """The ``distributed.Client`` behind ``executor`` (from ``Client.get_executor``), or None."""
    if "distributed" not in sys.modules:
        return None
    from distributed.cfexecutor import ClientExecutor

    return executor._client if isinstance(executor, ClientExecutor) else None


def _scheduler_name(client: Any) -> str:
    address = getattr(getattr(client, "scheduler", None), "address", None)
    return f"the Dask scheduler at {address}" if address else "the Dask scheduler"


def executor_lost(executor: cf.Executor) -> str | None:
    """Why ``executor`` can run no further cell (its Dask scheduler is gone), else None.

    A client that lost its scheduler cancels every future it holds and tries
    to reconnect for its connect timeout, then closes; a restarted scheduler
    knows nothing of the lost futures either, so in every state but
    ``running`` the grid cannot go on through this client.
    """
    client = _dask_client(executor)
    if client is None or client.status == "running":
        return None
    return (
        f"{_scheduler_name(client)} was lost (its client is {client.status}); start it again and run the same "
        "command, or resume with --executor local"
    )


def executor_failure(exc: BaseException, executor: cf.Executor) -> tuple[str, bool]:
    """One line on why the executor lost a cell's job with ``exc``, and whether that halts the grid.

    A Dask worker that died with the cell (``KilledWorker``) loses that cell
    only; a lost scheduler (a closed connection, a timeout talking to it)
    loses every cell, so it halts the grid.
    """
    name = type(exc).__name__
    first_line = (str(exc).strip().splitlines() or [""])[0]
    detail = f"{name}: {first_line[:200]}" if first_line else name
    lost = executor_lost(executor)
    if name == "KilledWorker":
        return (
            "the Dask worker that ran the cell died while it ran the cell (killed, out of memory, or its machine "
            f"went away; the scheduler gave up on the cell: {name}); run `albot1 bench` again to retry it",
            False,
        )
    if lost is not None:
        return f"{lost} ({detail})", True
    if name in ("CommClosedError", "TimeoutError", "CancelledError", "FutureCancelledError"):
        return f"the connection to the executor was lost: {detail}; run `albot1 bench` again to retry the cell", True
    return f"executor error: {detail}", False
