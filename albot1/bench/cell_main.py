"""Entry point of a cell's child process (forkserver target, or ``python -m albot1.bench.cell_main ARGS``).

The child makes itself killable and bounded before touching any data: it
exits when the runner dies (so a SIGKILLed runner leaves no orphan writing
into the store), caps its address space (``RLIMIT_AS`` at its start size
plus the cell's ``memory_mb``, so the libraries already mapped do not eat
the allowance) and sends its output to the cell log. Any exception is
written to ``.error.json`` in the run folder for the supervisor, which
alone writes ``FAILED.json``.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import resource
import signal
import sys
import threading
import traceback
from pathlib import Path
from typing import Any

ERROR_FILE = ".error.json"
EXIT_OK = 0
EXIT_EXCEPTION = 2
EXIT_MEMORY = 3
EXIT_INTERRUPTED = 4
EXIT_ORPHAN = 5


def _die_with_parent(parent_pid: int | None) -> None:
    """Exit when the runner dies.

    A forkserver child's parent is the forkserver, which itself outlives the
    runner while any child lives, so the child watches the runner directly:
    ``multiprocessing.parent_process()`` is the process that started it and
    its sentinel becomes ready when that process is gone. A subprocess child
    (``parent_pid`` given) uses the kernel's parent-death signal instead.
    """
    runner = multiprocessing.parent_process()
    if runner is not None:

        def watch() -> None:
            runner.join()
            os._exit(EXIT_ORPHAN)

        threading.Thread(target=watch, name="runner-watch", daemon=True).start()
    if parent_pid is not None and sys.platform.startswith("linux"):
        import ctypes

        pr_set_pdeathsig = 1
        ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, signal.SIGKILL, 0, 0, 0)
    if parent_pid is not None and os.getppid() != parent_pid:  # the parent died before the signal was armed
        raise SystemExit(EXIT_ORPHAN)


def _address_space_bytes() -> int:
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")


def limit_memory(memory_mb: float) -> int | None:
    """Cap the address space at its current size plus ``memory_mb``; returns the cap in bytes."""
    try:
        current = _address_space_bytes()
    except OSError:  # no /proc: not Linux; the time limit still applies
        return None
    cap = current + int(memory_mb * 2**20)
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    return cap


def _redirect_output(log_path: Path) -> None:
    sys.stdout.flush()
    sys.stderr.flush()
    fd = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    os.close(fd)


def _apply_environment(env: dict[str, str]) -> None:
    """Make the child's ALBOT1_* settings exactly the runner's (a forkserver may have started earlier)."""
    for name in [k for k in os.environ if k.startswith("ALBOT1_")]:
        if name not in env:
            del os.environ[name]
    os.environ.update(env)


def _write_error(run_dir: Path, kind: str, exc: BaseException) -> None:
    from albot1.runs.folder import write_json

    text = "".join(traceback.format_exception(exc))
    sys.stderr.write(text)
    sys.stderr.flush()
    write_json(run_dir / ERROR_FILE, {"kind": kind, "type": type(exc).__name__, "message": str(exc), "traceback": text})


def child_main(args: dict[str, Any]) -> int:
    """Run one cell; the exit code tells the supervisor how it ended (details in ``.error.json``)."""
    _die_with_parent(args.get("parent_pid"))
    run_dir = Path(args["runs_root"]) / args["cell"]["key"]
    _redirect_output(Path(args["log_path"]))
    _apply_environment(dict(args.get("env", {})))
    try:
        limit_memory(float(args["cell"]["memory_mb"]))
        # Imported here, inside the try: an import failure is this cell's recorded failure.
        from albot1.bench.cells import execute_cell, renderer_from_target
        from albot1.bench.grid import Cell

        preview = renderer_from_target(args.get("preview"))
        execute_cell(Cell.from_json(args["cell"]), Path(args["runs_root"]), preview=preview)
    except MemoryError as exc:
        _write_error(run_dir, "memory", exc)
        return EXIT_MEMORY
    except KeyboardInterrupt as exc:
        _write_error(run_dir, "interrupted", exc)
        return EXIT_INTERRUPTED
    except Exception as exc:
        if _caused_by_memory(exc):  # run_method wraps library errors in the method's error class
            _write_error(run_dir, "memory", exc)
            return EXIT_MEMORY
        _write_error(run_dir, "exception", exc)
        return EXIT_EXCEPTION
    return EXIT_OK


def _caused_by_memory(exc: BaseException) -> bool:
    seen: set[int] = set()
    current: BaseException | None = exc
    while current is not None and id(current) not in seen:
        if isinstance(current, MemoryError):
            return True
        seen.add(id(current))
        current = current.__cause__ or current.__context__
    return False


def process_entry(args: dict[str, Any]) -> None:
    """``multiprocessing.Process`` target."""
    raise SystemExit(child_main(args))


if __name__ == "__main__":
    raise SystemExit(child_main(json.loads(Path(sys.argv[1]).read_text())))
