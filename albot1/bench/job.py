"""The function every executor runs for one cell: launch the limited child, then judge and record.

It runs wherever the executor puts it (a thread of the local pool, a Dask
worker); only this function writes ``FAILED.json``, so every way a cell can
end -- result, exception, memory cap, timeout, crash -- is recorded by one
piece of code with one vocabulary.
"""

from __future__ import annotations

import json
import signal
import socket
import time
from pathlib import Path

from albot1.bench.cell_main import ERROR_FILE, EXIT_OK
from albot1.bench.grid import Cell, CellOutcome, FailureKind
from albot1.bench.limits import ChildExit, run_limited
from albot1.bench.store import ATTEMPT, LOG, ResultsStore
from albot1.records import AttemptRecord
from albot1.runs.folder import write_record


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def judge(cell: Cell, store: ResultsStore, ended: ChildExit) -> tuple[FailureKind, str] | None:
    """None when the cell completed, else (kind, reason); the traceback is already in the cell log."""
    run_dir = store.run_dir(cell.key)
    error_path = run_dir / ERROR_FILE
    error = None
    if error_path.is_file():
        try:
            error = json.loads(error_path.read_text())
        except json.JSONDecodeError:
            error = None
        error_path.unlink(missing_ok=True)
    if ended.timed_out:
        return "timeout", f"time limit exceeded: no result after {cell.time_s:g} s (killed)"
    if ended.exit_code is not None and ended.exit_code < 0:
        name = _signal_name(-ended.exit_code)
        hint = {
            "SIGKILL": " (killed from outside, e.g. by the kernel's out-of-memory killer)",
            "SIGSEGV": " (a native library crashed)",
            "SIGABRT": f" (a native library aborted; a failed allocation under the "
            f"{cell.memory_mb:g} MB memory limit does this)",
        }.get(name, "")
        return "crash", f"the cell process died from {name}{hint}"
    if error is not None:
        kind: FailureKind = error.get("kind", "exception")
        message = f"{error.get('type')}: {error.get('message')}"
        if kind == "memory":
            message = f"memory limit exceeded ({cell.memory_mb:g} MB address space): {message}"
        return kind, message
    if ended.exit_code != EXIT_OK:
        return "crash", f"the cell process exited with code {ended.exit_code} without an error report"
    if not store.is_complete(cell.key):
        return "exception", "the cell process finished but left no complete run (DONE and metrics.json)"
    return None


def run_cell_job(cell: Cell, results_root: str, preview: str | None = None) -> CellOutcome:
    """Run ``cell`` into the store at ``results_root`` and record how it ended.

    ``preview``: the ``module:function`` that draws each run's preview (None: no preview).
    """
    store = ResultsStore(results_root)
    run_dir = store.prepare(cell)
    ended = run_limited(cell, store.runs, run_dir / LOG, preview=preview)
    verdict = judge(cell, store, ended)
    if verdict is None:
        write_record(
            run_dir / ATTEMPT,
            AttemptRecord(
                elapsed_s=ended.elapsed_s,
                host=socket.gethostname(),
                finished=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
            ),
        )
        return CellOutcome.of(cell, "done", ended.elapsed_s)
    kind, reason = verdict
    store.record_failure(cell, reason, kind, exit_code=ended.exit_code, elapsed_s=ended.elapsed_s)
    return CellOutcome.of(cell, "failed", ended.elapsed_s, reason, kind)


def results_path(root: Path) -> str:
    """Absolute path given to jobs (Dask workers must see the same folder at the same path)."""
    return str(root.resolve())
