"""The function every executor runs for one cell: launch the limited child, then judge and record.

It runs wherever the executor puts it (a thread of the local pool, a Dask
worker); only this function writes ``FAILED.json``, so every way a cell can
end -- result, exception, memory limit, timeout, crash, a lost process pool,
a full disk -- is recorded by one piece of code with one vocabulary.
"""

from __future__ import annotations

import errno
import json
import os
import signal
import socket
import sys
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

from albot1 import versions
from albot1.bench.cell_main import ERROR_FILE, EXIT_OK, EXIT_STORAGE, STORAGE_ERRNOS, storage_error
from albot1.bench.grid import Cell, CellOutcome, FailureKind
from albot1.bench.limits import ChildExit, check_launching, run_limited
from albot1.bench.store import ATTEMPT, LOG, ResultsStore
from albot1.records import AttemptRecord
from albot1.runs.folder import write_record


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


#: Why a cell process died from a signal, as far as the signal tells.
_SIGNAL_HINTS = {
    "SIGKILL": " (killed from outside, e.g. by the kernel's out-of-memory killer or by a person)",
    "SIGTERM": " (stopped from outside: the cell pool was shut down, or someone terminated it)",
    "SIGINT": " (interrupted: Ctrl-C)",
    "SIGHUP": " (its terminal went away)",
    "SIGSEGV": " (a native library crashed)",
    "SIGBUS": " (a native library crashed)",
    "SIGABRT": " (a native library aborted)",
}


def judge(cell: Cell, store: ResultsStore, ended: ChildExit) -> tuple[FailureKind, str] | None:
    """None when the cell completed, else (kind, reason); the traceback is already in the cell log."""
    run_dir = store.run_dir(cell.key)
    error_path = run_dir / ERROR_FILE
    error = None
    if error_path.is_file():
        try:
            error = json.loads(error_path.read_text())
        except (OSError, json.JSONDecodeError):
            error = None
        error_path.unlink(missing_ok=True)
    if error is None and _stopped(ended) and store.is_complete(cell.key):
        # The kill landed after the child had written its whole result (DONE and metrics.json, each by atomic
        # rename), while it was exiting: the cell is complete, as `albot1 report` and the next `albot1 bench`
        # read its folder. A timeout recorded beside it made the bench print FAILED for a cell the report
        # counted complete (a FAILED.json beside a complete result), and the reason said "no result".
        return None
    if ended.abandoned:
        return "interrupted", (
            "the runner gave the cell up while it ran (its Dask client closed, e.g. on Ctrl-C, or cancelled the "
            "cell after a halt), so the cell was stopped; run `albot1 bench` again to retry it"
        )
    if ended.timed_out:
        return "timeout", f"time limit exceeded: no result after {cell.time_s:g} s (killed)"
    if ended.memory_exceeded:
        return "memory", (
            f"memory limit exceeded: resident memory reached {ended.peak_rss_mb or 0:.1f} MB, over the cell's "
            f"limit of {cell.memory_mb:g} MB (killed)"
        )
    if ended.pool_lost is not None:
        during = "while the cell ran, so the cell was stopped" if ended.started else "before it started the cell"
        return "executor", (
            f"the cell process pool was shut down: its forkserver {ended.pool_lost} {during}; "
            "run `albot1 bench` again to retry it"
        )
    if ended.exit_code is not None and ended.exit_code < 0:
        name = _signal_name(-ended.exit_code)
        return "crash", f"the cell process was killed by {name}{_SIGNAL_HINTS.get(name, '')}"
    if error is not None:
        kind: FailureKind = error.get("kind", "exception")
        message = f"{error.get('type')}: {error.get('message')}"
        if kind == "memory":
            message = f"out of memory (an allocation was refused): {message}"
        if kind == "interrupted":
            message = "interrupted (SIGINT, e.g. Ctrl-C) before the cell finished; run `albot1 bench` again to retry it"
        if kind == "storage" or error.get("errno") in STORAGE_ERRNOS:
            return "storage", f"cannot write the results: {_errno_text(error.get('errno'))}: {message}"
        return kind, message
    if ended.exit_code == EXIT_STORAGE:
        return "storage", f"cannot write the results in {store.runs}: {file_system_state(store.runs)}"
    if ended.exit_code != EXIT_OK:
        return "crash", f"the cell process exited with code {ended.exit_code} without an error report"
    if not store.is_complete(cell.key):
        return "exception", (
            "the cell process exited with code 0 but left no complete run (DONE and metrics.json) and no error "
            "report: something in it ended the process early (a method calling os._exit(0)?)"
        )
    return None


def _stopped(ended: ChildExit) -> bool:
    """Whether the child was stopped from outside (a limit, a lost pool, a signal) rather than exiting itself."""
    signalled = ended.exit_code is not None and ended.exit_code < 0
    return ended.timed_out or ended.memory_exceeded or ended.pool_lost is not None or signalled


def file_system_state(folder: Path) -> str:
    """Why writes in ``folder`` may fail, as far as the file system says (full, read-only), for a failure reason."""
    try:
        stats = os.statvfs(folder)
    except OSError as exc:
        return f"its file system cannot be queried ({(exc.strerror or str(exc)).lower()})"
    if stats.f_flag & os.ST_RDONLY:
        return "read-only file system"
    free = stats.f_bavail * stats.f_frsize
    if stats.f_favail == 0 and stats.f_files > 0:
        return "no space left on device (no free inodes)"
    if free < 16 * 2**20:
        return f"no space left on device ({free / 2**20:.1f} MiB free)"
    return f"a write failed although {free / 2**20:.0f} MiB are free now (quota? space freed since?)"


def _errno_text(number: object) -> str:
    if isinstance(number, int) and number in errno.errorcode:
        return os.strerror(number).lower()
    return "the file system refused a write"


def run_cell_job(cell: Cell, results_root: str, preview: str | None = None) -> CellOutcome:
    """Run ``cell`` into the store at ``results_root`` and record how it ended.

    ``preview``: the ``module:function`` that draws each run's preview (None: no preview).
    A results folder that cannot be written (full, read-only) fails the cell
    with kind ``storage`` and halts the grid; nothing about it raises.
    """
    check_launching(cell)  # before its folder is made: a cell the stopping runner never started leaves none
    store = ResultsStore(results_root)
    mismatch = _worker_code_mismatch(cell)
    if mismatch is not None:
        problem = store.record_failure(cell, mismatch, "executor")
        reason = mismatch if problem is None else f"{mismatch} [not recorded: {problem}]"
        return CellOutcome.of(cell, "failed", 0.0, reason, "executor", halts_grid=True)
    try:
        run_dir = store.prepare(cell)
        ended = run_limited(cell, store.runs, run_dir / LOG, preview=preview, abandoned=_given_up_by_dask())
    except OSError as exc:
        return _storage_failure(store, cell, exc, 0.0)
    verdict = judge(cell, store, ended)
    if verdict is None:
        try:
            write_record(
                run_dir / ATTEMPT,
                AttemptRecord(
                    elapsed_s=ended.elapsed_s,
                    host=socket.gethostname(),
                    finished=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                    launch_s=ended.launch_s,
                ),
            )
        except OSError as exc:  # the run is complete; only its wall-time record did not fit
            return _storage_failure(store, cell, exc, ended.elapsed_s, completed=True)
        return CellOutcome.of(cell, "done", ended.elapsed_s)
    kind, reason = verdict
    problem = store.record_failure(
        cell, reason, kind, exit_code=ended.exit_code, elapsed_s=ended.elapsed_s, launch_s=ended.launch_s
    )
    if problem is not None:
        reason = f"{reason} [not recorded: {problem}]"
    # An interrupted cell halts the grid too: the Ctrl-C (or the SIGINT a SIGTERM was handed on as) that stopped
    # it stopped the forkserver as well, and this thread's next cell restarted the server (its preload: seconds
    # to a minute) and ran on, unwatched by the runner, which waited for it (the pool's shutdown) before exiting.
    halts = kind in ("storage", "interrupted") or ended.pool_lost is not None
    return CellOutcome.of(cell, "failed", ended.elapsed_s, reason, kind, halts_grid=halts)


def _dask_worker() -> Any | None:
    """The Dask worker running this task, or None outside one (distributed not imported, or not in a task)."""
    if "distributed" not in sys.modules:
        return None
    from distributed import get_worker

    try:
        return get_worker()
    except ValueError:  # not inside a Dask task
        return None


def _given_up_by_dask() -> Callable[[], bool] | None:
    """On a Dask worker: whether the scheduler has given this task up since (None elsewhere).

    A runner's client that closes (Ctrl-C, a SIGTERM) or cancels a running cell (after a halt) makes the
    scheduler cancel its task, but the worker's thread cannot be stopped: the cell ran on and wrote its
    folder after the runner had released the results folder's lock, and a re-run started then (as the
    runner's last line invites) ran the same cell into the same folder at the same time.
    """
    worker = _dask_worker()
    if worker is None:
        return None
    key = worker.get_current_task()

    def given_up() -> bool:
        task = worker.state.tasks.get(key)
        return task is None or task.state in ("cancelled", "released", "forgotten")

    return given_up


def _worker_code_mismatch(cell: Cell) -> str | None:
    """Why this Dask worker must not run ``cell``: its albot1 code or a library is not what the cell's key names.

    The key holds the planning machine's code version and library versions (:attr:`Cell.versions`); a worker
    with other code or another library would compute a result the key does not name (its cells would fail one
    by one, :func:`albot1.bench.cells.check_versions`). Checked on Dask workers only: the local executor runs
    jobs in the runner's own process, whose code and libraries planned the keys.
    """
    worker = _dask_worker()
    if worker is None:
        return None
    where = f"the Dask worker {worker.address} on {socket.gethostname()}"
    version = versions.code_version()
    if version != cell.code_version:
        return (
            f"{where} has albot1 code {version}, but the cells were planned with code {cell.code_version}; install "
            "the same code on every worker (see `albot1 --version`)"
        )
    installed = versions.library_versions()
    other = [name for name in sorted(installed) if name in cell.versions and installed[name] != cell.versions[name]]
    if not other:
        return None
    found = ", ".join(f"{name} {installed[name]} (planned with {cell.versions[name]})" for name in other)
    return f"{where} has {found}; install the same library versions on every worker"


def _storage_failure(
    store: ResultsStore, cell: Cell, exc: OSError, elapsed_s: float, *, completed: bool = False
) -> CellOutcome:
    """The outcome of a cell whose supervisor met an OSError writing the results or starting the cell process.

    A full or read-only file system halts the grid (kind ``storage``); any
    other OSError (no process could be started, say) fails this cell only.
    """
    storage = storage_error(exc) is not None
    what = (exc.strerror or str(exc)).lower()
    if completed:
        reason = f"cannot write {exc.filename}: {what} (the run itself is complete; only its attempt.json is missing)"
        return CellOutcome.of(cell, "done", elapsed_s, reason, "storage", halts_grid=storage)
    if storage:
        reason = f"cannot write the results: {what}: {exc.filename or store.runs}"
    else:
        reason = f"cannot start the cell: {type(exc).__name__}: {exc}"
    kind: FailureKind = "storage" if storage else "executor"
    problem = store.record_failure(cell, reason, kind, elapsed_s=elapsed_s, traceback_text=traceback.format_exc())
    if problem is not None:
        reason = f"{reason} [not recorded: {problem}]"
    return CellOutcome.of(cell, "failed", elapsed_s, reason, kind, halts_grid=storage)


def results_path(root: Path) -> str:
    """Absolute path given to jobs (Dask workers must see the same folder at the same path)."""
    return str(root.resolve())
