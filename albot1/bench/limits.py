"""Run one cell in a fresh child process under a time and a resident-memory limit.

Why a fresh process per cell: a timeout can only be enforced by killing, a
process's resident memory is what a memory limit can measure, a segfault in
a C++ library must not take the runner down, and ``peak_mb`` (``ru_maxrss``)
is only the cell's own peak in a process of its own.

The limits are enforced from outside: the supervisor polls the child's
resident memory (and that of any process the child started,
:func:`albot1.processes.supervise`) every :data:`POLL_S` seconds and kills
the tree when it passes ``memory_mb`` or when ``time_s`` has passed. An
address-space limit inside the child would break the compiled libraries the
methods load (docs/benchmarking.md, "Memory limit").

Two launchers, one contract (``cell_main.child_main``):

* ``forkserver`` (default): children fork from a server that has already
  imported numpy, matplotlib, the loaders, the metrics and the method
  modules (:mod:`albot1.bench.preload`), so starting a cell costs
  milliseconds instead of seconds of imports.
* ``subprocess`` (``python -m albot1.bench.cell_main``): used where
  multiprocessing may not fork children (inside a daemonic process, such as
  a worker of a remote Dask scheduler).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from multiprocessing.connection import wait as wait_ready
from pathlib import Path
from typing import Any

import psutil

from albot1 import processes
from albot1.bench.cell_main import process_entry
from albot1.bench.grid import Cell
from albot1.processes import Stop, kill_tree
from albot1.runs.folder import write_json

PRELOAD = ["__main__", "albot1.bench.preload"]
#: The methods the forkserver preloads, comma-separated (unset: every one); read by :mod:`albot1.bench.preload`.
METHODS_ENV = "ALBOT1_PRELOAD_METHODS"
#: How often the supervisor checks the child's resident memory and the clock (s). A cell may
#: overshoot its memory limit by what it allocates in this time.
POLL_S = 0.05
_FORKSERVER: Any = None
#: Held while the forkserver is started with its preload list in the environment (:func:`start_forkserver`).
_START_LOCK = threading.Lock()
#: Held while a forkserver child is started or its exit status read (:class:`ForkserverChild`).
_STATUS_LOCK = threading.Lock()
#: Set while the runner stops (:func:`stop_launching`).
_STOPPING = threading.Event()


class CellNotStarted(Exception):  # noqa: N818 -- a signal to the runner, not an error
    """The runner is stopping, so the cell was not started: it stays to do, like a cell the grid never reached."""


def stop_launching() -> None:
    """Start no cell and no forkserver in this process from now on (until :func:`allow_launching`).

    Why: Ctrl-C reaches the runner, its cells and their forkserver at once. A cell thread that was past the
    grid's halt check (its previous cell ended a moment before) started the forkserver again (its preload:
    seconds to a minute), forked its next cell and supervised it to its end, while the runner, interrupted,
    waited for that thread before it could exit: 9-116 s after a Ctrl-C (``benchmarks/stop_signals.py``).
    """
    _STOPPING.set()


def allow_launching() -> None:
    """Cells may be started again (a new grid in this process)."""
    _STOPPING.clear()


def check_launching(cell: Cell) -> None:
    """CellNotStarted when the runner is stopping (:func:`stop_launching`)."""
    if _STOPPING.is_set():
        raise CellNotStarted(cell.key)


@dataclass(frozen=True)
class ChildExit:
    """How the child ended.

    ``exit_code``: its exit code (negative = killed by that signal; None when
    the supervisor killed it for a limit). ``stopped``: the limit that made
    the supervisor kill it. ``peak_rss_mb``: the largest resident memory the
    supervisor saw (the child and its own children). ``pool_lost``: how the
    forkserver that started the child ended, when it died under the running
    cell (the child was then stopped and its exit status is unknown).
    ``abandoned``: the supervisor stopped the child because the runner gave
    the cell up (a Dask client that closed or cancelled it: ``run_limited``'s ``abandoned``).
    ``started``: False when the forkserver was lost before it forked the child
    (``pool_lost`` says how; e.g. the Ctrl-C that stopped the grid reached it).

    ``elapsed_s`` is the cell's wall time from the moment its process existed
    (the moment its time limit starts counting) to its end; ``launch_s`` the
    time before that, spent starting the process. Why apart: a forkserver
    still starting makes its first children wait for its preload (imports and
    every method's warm-up: 46 s on a cold numba cache, once per grid), which
    is no cost of the cells that happen to be forked first.
    """

    exit_code: int | None
    timed_out: bool
    elapsed_s: float
    memory_exceeded: bool = False
    peak_rss_mb: float | None = None
    pool_lost: str | None = None
    launch_s: float | None = None
    abandoned: bool = False
    started: bool = True


class ForkserverChild:
    """A started forkserver child whose exit status is read safely from any number of threads.

    Python 3.11's ``Process.start()`` polls every unreaped child of the
    process (``multiprocessing.process._cleanup``), so a cell starting in one
    runner thread could read the exit status of a cell ending in another at
    the same moment as that cell's own thread: the status pipe holds it once,
    the second reader gets EOF and multiprocessing reports exit code 255 for
    a child that exited 0 (measured: 17 of 600 short children under two
    threads; none with :data:`_STATUS_LOCK`; CPython issue 140867). Starting
    and status reads therefore hold one lock; waiting does not need it.
    """

    def __init__(self, target: Callable[..., object], args: tuple[Any, ...], name: str) -> None:
        self._proc = _forkserver().Process(target=target, args=args, name=name, daemon=False)
        with _STATUS_LOCK:
            # Asked again under the lock: a thread waits here while another's fork waits for the server's preload;
            # when a Ctrl-C ends that server, ``start`` would start a new one (multiprocessing's own restart).
            if _STOPPING.is_set():
                raise CellNotStarted(name)
            self._proc.start()

    @property
    def pid(self) -> int:
        return int(self._proc.pid)

    def ended(self, timeout: float) -> bool:
        """Wait up to ``timeout`` s; whether the child has exited."""
        wait_ready([self._proc.sentinel], timeout)  # waits for the pipe without reading the status
        with _STATUS_LOCK:
            return not self._proc.is_alive()

    def exit_code(self) -> int | None:
        """The exit code (negative: killed by that signal; 255: the forkserver gave no status)."""
        with _STATUS_LOCK:
            code = self._proc.exitcode
        return None if code is None else int(code)

    def kill(self) -> None:
        self._proc.kill()


def _forkserver() -> Any:
    global _FORKSERVER
    if _FORKSERVER is None:
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(PRELOAD)
        _FORKSERVER = ctx
    return _FORKSERVER


def start_forkserver(methods: Iterable[str] | None = None) -> None:
    """Start the cell forkserver now (it computes the code version first thing, then imports).

    The runner calls this before planning, so that the code version its
    cells are forked with and the one the plan's keys use are taken moments
    apart rather than a planning pass apart. ``methods``: the registered
    methods the server preloads (None: every one; :mod:`albot1.bench.preload`).
    A server already running is kept as it is.
    """
    if launcher() == "forkserver":
        from multiprocessing import forkserver, resource_tracker

        _forkserver()
        with _START_LOCK, _preloading(methods):  # cell threads call this too: one environment change at a time
            # The server's resource tracker first: starting it unblocks SIGINT in this thread (multiprocessing's
            # own hold, released with SIG_UNBLOCK), which would undo the hold below.
            resource_tracker.ensure_running()
            with _sigint_held():
                forkserver.ensure_running()


@contextmanager
def _preloading(methods: Iterable[str] | None) -> Iterator[None]:
    """``ALBOT1_PRELOAD_METHODS`` set to ``methods`` while the server starts (it inherits this environment)."""
    if methods is None:
        yield
        return
    before = os.environ.get(METHODS_ENV)
    os.environ[METHODS_ENV] = ",".join(sorted(set(methods)))
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(METHODS_ENV, None)
        else:
            os.environ[METHODS_ENV] = before


@contextmanager
def _sigint_held() -> Iterator[None]:
    """SIGINT blocked in this thread while it starts the server, which inherits the mask through ``exec``.

    Ctrl-C reaches the whole process group, the server too. In its first ~0.1 s (Python's start, ``site``,
    multiprocessing's imports: before :mod:`albot1.bench.preload` can take SIGINT's default action) a Ctrl-C
    printed a KeyboardInterrupt traceback from the server above the runner's one line, and so did the SIGINT
    the runner hands on after a SIGTERM. Blocked, it waits until the preload's first line unblocks it: the
    server then ends at once and silently, as during the rest of its preload. Ignoring it instead would lose
    it: the server would preload on (tens of seconds of cold compiles) after the runner stopped. Only this
    thread's mask changes: a SIGINT to the runner is handled by its main thread as usual (or, when this is the
    main thread, a few milliseconds later).
    """
    held = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


def launcher() -> str:
    """``forkserver`` where this process may start children, else ``subprocess``."""
    if sys.platform.startswith("linux") and not multiprocessing.current_process().daemon:
        return "forkserver"
    return "subprocess"


def child_args(cell: Cell, runs_root: Path, log_path: Path, preview: str | None = None) -> dict[str, Any]:
    with _START_LOCK:  # another cell's thread may be setting and removing ALBOT1_PRELOAD_METHODS (_preloading)
        env = {k: v for k, v in os.environ.items() if k.startswith("ALBOT1_")}
    return {
        "cell": cell.to_json(),
        "runs_root": str(runs_root),
        "log_path": str(log_path),
        "preview": preview,
        "parent_pid": os.getpid(),
        "env": env,
        # a forkserver started earlier lacks folders put on the path since (an installed plugin's metadata)
        "sys_path": list(sys.path),
    }


def watch(pid: int) -> psutil.Process | None:
    """The child to supervise (None when it has already exited)."""
    try:
        return psutil.Process(pid)
    except psutil.Error:
        return None


def supervise(
    process: psutil.Process | None, ended: Callable[[float], bool], time_s: float, memory_mb: float
) -> tuple[Stop | None, float]:
    """:func:`albot1.processes.supervise` at the cells' :data:`POLL_S` (the tree is stopped by ``kill_tree``).

    ``ended(timeout)`` waits up to ``timeout`` s and says whether the child has
    exited; returns the limit that stopped it (None: it ended by itself) and
    the peak resident memory seen, MiB.
    """
    return processes.supervise(process, ended, time_s=time_s, memory_mb=memory_mb, poll_s=POLL_S)


def _server_fate(server: psutil.Process | None, wait_s: float = 2.0) -> str | None:
    """None while the forkserver ``server`` runs; else how it ended ("was killed by SIGKILL", ...).

    Asked when a cell's exit status came back as 255, which is also what
    multiprocessing reports when the server's pipe closed. A killed process
    closes its pipes a moment before it is a zombie, so this looks for up to
    ``wait_s`` seconds. Its exit status is read with ``WNOWAIT``, without
    reaping it: multiprocessing reaps it when it starts a new one.
    """
    if server is None:
        return None
    deadline = time.monotonic() + wait_s
    while True:
        try:
            info = os.waitid(os.P_PID, server.pid, os.WEXITED | os.WNOHANG | os.WNOWAIT)
        except ChildProcessError:  # reaped already, or not this process's child
            return None if server.is_running() else "is gone"
        if info is not None:
            break
        if time.monotonic() > deadline:
            return None
        time.sleep(0.02)
    if info.si_code in (os.CLD_KILLED, os.CLD_DUMPED):
        try:
            name = signal.Signals(info.si_status).name
        except ValueError:
            name = f"signal {info.si_status}"
        return f"was killed by {name}"
    return f"exited with code {info.si_status}"


def _parent_of(process: psutil.Process | None) -> psutil.Process | None:
    try:
        return process.parent() if process is not None else None
    except psutil.Error:
        return None


def _unless_abandoned(
    ended: Callable[[float], bool], process: psutil.Process | None, abandoned: Callable[[], bool] | None
) -> tuple[Callable[[float], bool], list[bool]]:
    """``ended`` that first kills the child's tree once ``abandoned()`` says so; the list says whether it did."""
    gave_up: list[bool] = []

    def check(timeout: float) -> bool:
        if abandoned is not None and not gave_up and abandoned():
            gave_up.append(True)
            if process is not None:
                kill_tree(process)
        return ended(timeout)

    return check, gave_up


def run_limited(
    cell: Cell,
    runs_root: Path,
    log_path: Path,
    *,
    how: str | None = None,
    preview: str | None = None,
    abandoned: Callable[[], bool] | None = None,
) -> ChildExit:
    """Run ``cell`` in a child; kill it when it passes ``cell.time_s`` seconds or ``cell.memory_mb`` resident.

    ``preview`` is the ``module:function`` of the run preview renderer (``bench.cells.renderer_target``).
    The child's wall time is counted from the moment it exists (:class:`ChildExit`: ``elapsed_s``, ``launch_s``).
    ``abandoned`` (None: never) is asked at every poll whether the runner gave the cell up; the child is
    then killed (:attr:`ChildExit.abandoned`), so that no cell of a runner gone writes into its results.
    """
    args = child_args(cell, runs_root, log_path, preview)
    start = time.monotonic()
    check_launching(cell)
    if (how or launcher()) == "forkserver":
        # The forkserver, not this process, is the child's parent; it exits when this process dies.
        args["parent_pid"] = None
        start_forkserver((cell.method,))  # where no runner started it (a Dask worker), or after it was lost
        check_launching(cell)  # asked again: a server started anew makes the fork below wait for its preload
        # Returns once the server has forked the child: after its preload when the server is still starting.
        try:
            forked = ForkserverChild(process_entry, (args,), name=f"cell-{cell.key}")
        except (EOFError, ConnectionError) as exc:  # its pipe closed before it sent the child's pid
            fate = f"ended ({type(exc).__name__} on its pipe)"
            return ChildExit(None, False, 0.0, pool_lost=fate, launch_s=time.monotonic() - start, started=False)
        launched = time.monotonic()
        process = watch(forked.pid)
        server = _parent_of(process)
        ended, gave_up = _unless_abandoned(forked.ended, process, abandoned)
        stop, peak = supervise(process, ended, cell.time_s, cell.memory_mb)
        if stop is not None and process is None:
            forked.kill()
        while not forked.ended(POLL_S):
            pass
        code = None if stop is not None else forked.exit_code()
        lost = _server_fate(server) if code == 255 else None  # 255: the forkserver's pipe closed, no status
        if lost is not None and process is not None:
            kill_tree(process)  # the cell may outlive its server: stop it before it writes anything more
        return ChildExit(
            code,
            stop == "timeout",
            time.monotonic() - launched,
            stop == "memory",
            peak,
            lost,
            launched - start,
            abandoned=bool(gave_up),
        )
    args_file = runs_root / cell.key / ".child-args.json"
    write_json(args_file, args)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    with subprocess.Popen(
        [sys.executable, "-m", "albot1.bench.cell_main", str(args_file)],
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    ) as child:
        launched = time.monotonic()

        def child_ended(timeout: float) -> bool:
            try:
                child.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                return False
            return True

        process = watch(child.pid)
        ended, gave_up = _unless_abandoned(child_ended, process, abandoned)
        stop, peak = supervise(process, ended, cell.time_s, cell.memory_mb)
        if stop is not None and process is None:
            child.kill()
        code = child.wait()
    args_file.unlink(missing_ok=True)
    return ChildExit(
        None if stop is not None else code,
        stop == "timeout",
        time.monotonic() - launched,
        stop == "memory",
        peak,
        launch_s=launched - start,
        abandoned=bool(gave_up),
    )
