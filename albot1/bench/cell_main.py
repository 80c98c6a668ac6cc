"""Entry point of a cell's child process (forkserver target, or ``python -m albot1.bench.cell_main ARGS``).

The child makes itself killable before touching any data: it exits when
the runner dies (so a SIGKILLed runner leaves no orphan writing into the
store) and sends its output to the cell log. Its time and memory limits are
enforced from outside by the supervisor (:mod:`albot1.bench.limits`). Any
exception is written to ``.error.json`` in the run folder for the
supervisor, which alone writes ``FAILED.json``; when the results folder
cannot be written (disk full, read-only) the exit code says so, as the
error file itself may not fit.
"""

from __future__ import annotations

import errno
import gc
import importlib
import json
import multiprocessing
import os
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
EXIT_STORAGE = 6
#: OS errors that mean "the results folder cannot take more": the grid cannot go on until someone frees space.
STORAGE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EFBIG})


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


def _apply_import_path(paths: list[str]) -> None:
    """Make the child's import path the runner's, and read the method registry again if anything changed.

    The forkserver is started once per runner process and forks every cell
    from its own state: a folder put on the runner's path after it started (a
    plugin distribution installed into a running session, a notebook's path)
    would otherwise be missing from the cells, and the registry it read at its
    start would miss a plugin installed since. The registry is read again only
    when the path or a folder on it changed since the server read it
    (:func:`~albot1.methods.registry.forget_registry_if_changed`): reading the
    entry points imports nothing but reads every distribution's metadata, ~17 ms
    of CPU in every cell.
    """
    if paths and paths != sys.path:
        sys.path[:] = paths  # the runner's path, whole: a folder the runner dropped since (an old plugin) goes too
        importlib.invalidate_caches()
    from albot1.methods.registry import forget_registry_if_changed

    forget_registry_if_changed()


def _write_error(run_dir: Path, kind: str, exc: BaseException) -> None:
    from albot1.runs.folder import write_json

    text = "".join(traceback.format_exception(exc))
    try:  # the cell log, on the same file system: it may be full
        sys.stderr.write(text)
        sys.stderr.flush()
    except OSError:
        pass
    storage = storage_error(exc)
    write_json(
        run_dir / ERROR_FILE,
        {
            "kind": kind,
            "type": type(exc).__name__,
            "message": str(exc),
            "errno": storage.errno if storage is not None else None,
            "traceback": text,
        },
    )


class _Sigint:
    """Whether SIGINT reached this cell (``watched``: the cell's handler notes it)."""

    watched = False
    received = False


def _note_sigint() -> None:
    """Note SIGINT before raising KeyboardInterrupt as Python does, so that Ctrl-C is told from a raised one.

    A method (a third-party plugin) may raise KeyboardInterrupt itself; recorded as "interrupted (Ctrl-C)"
    that reads as if someone had stopped the grid. Left alone when SIGINT does not raise KeyboardInterrupt
    today (ignored, or another handler).
    """
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        return

    def note(signum: int, frame: object) -> None:
        _Sigint.received = True
        raise KeyboardInterrupt

    signal.signal(signal.SIGINT, note)
    _Sigint.watched = True


def child_main(args: dict[str, Any]) -> int:
    """Run one cell; the exit code tells the supervisor how it ended (details in ``.error.json``)."""
    _die_with_parent(args.get("parent_pid"))
    _note_sigint()
    run_dir = Path(args["runs_root"]) / args["cell"]["key"]
    try:
        _redirect_output(Path(args["log_path"]))
        _apply_environment(dict(args.get("env", {})))
        _apply_import_path(list(args.get("sys_path", [])))
        # Imported here, inside the try: an import failure is this cell's recorded failure.
        from albot1.bench.cells import execute_cell, renderer_from_target
        from albot1.bench.grid import Cell

        preview = renderer_from_target(args.get("preview"))
        execute_cell(Cell.from_json(args["cell"]), Path(args["runs_root"]), preview=preview)
    except BaseException as exc:  # noqa: BLE001 -- every way out is reported by its exit code
        return _report(run_dir, exc)
    return EXIT_OK


def _report(run_dir: Path, exc: BaseException) -> int:
    """Write ``.error.json`` for ``exc`` and return the exit code that names its kind."""
    if isinstance(exc, SystemExit) and isinstance(exc.code, int):
        return exc.code
    if storage_error(exc) is not None:
        kind, code = "storage", EXIT_STORAGE
    elif isinstance(exc, KeyboardInterrupt) and (_Sigint.received or not _Sigint.watched):
        kind, code = "interrupted", EXIT_INTERRUPTED
    elif isinstance(exc, KeyboardInterrupt):  # raised by code in the cell, no Ctrl-C: that code's failure
        raised = KeyboardInterrupt("raised in the cell without a Ctrl-C (no SIGINT reached it): by the method?")
        raised.__cause__ = exc
        exc, kind, code = raised, "exception", EXIT_EXCEPTION
    elif _caused_by_memory(exc):  # run_method wraps library errors in the method's error class
        kind, code = "memory", EXIT_MEMORY
    elif _install_failure(exc):  # a broken install, or one changed under the grid: never allowed, retried
        kind, code = "executor", EXIT_EXCEPTION
    else:
        kind, code = "exception", EXIT_EXCEPTION
    try:
        _write_error(run_dir, kind, exc)
    except OSError:  # the error file does not fit either (disk full): the exit code alone must tell
        return EXIT_STORAGE
    return code


def _install_failure(exc: BaseException) -> bool:
    """Whether ``exc`` or an error in its chain is an ``InstallError`` (a program that cannot start, a plan mismatch).

    Looked up in ``sys.modules``, not imported: such an error was raised by the loaded module, and a cell
    whose imports failed must still have its failure recorded. The chain, not only ``exc``: a method's run
    wraps what its program said in the method's own error class (:func:`albot1.runs.execute.run_method`).
    """
    errors = sys.modules.get("albot1.errors")
    return errors is not None and any(isinstance(current, errors.InstallError) for current in _chain(exc))


def storage_error(exc: BaseException) -> OSError | None:
    """The OSError in ``exc``'s chain that says the file system cannot take more (ENOSPC, EDQUOT, EROFS, EFBIG)."""
    for current in _chain(exc):
        if isinstance(current, OSError) and current.errno in STORAGE_ERRNOS:
            return current
    return None


def _caused_by_memory(exc: BaseException) -> bool:
    return any(isinstance(current, MemoryError) for current in _chain(exc))


def _chain(exc: BaseException) -> list[BaseException]:
    """``exc`` and its causes and contexts, each once."""
    out: list[BaseException] = []
    seen: set[int] = set()
    current: BaseException | None = exc
    while current is not None and id(current) not in seen:
        out.append(current)
        seen.add(id(current))
        current = current.__cause__ or current.__context__
    return out


def freeze_inherited_heap() -> None:
    """Move every object this forked cell inherited out of the cycle collector's generations (``gc.freeze``).

    A forkserver child inherits the server's heap: about 330,000 objects
    after the joint warm-up of the kernels. Frozen, as the ``gc``
    documentation advises for a fork that does not exec, they are never
    walked by the cell's collections, which see only what the cell
    allocates, and never touched (so never copied) by them (issue 24:
    before, a full collection in the cell walked them all, 0.2 s of a
    places cell's ``finish_s`` on an idle machine). Done here, in the
    child, rather than in the server, so that a test process that imports
    :mod:`albot1.bench.preload` keeps its collector as it was.
    """
    gc.freeze()


def process_entry(args: dict[str, Any]) -> None:
    """``multiprocessing.Process`` target (a forkserver child): freeze the inherited heap, then run the cell."""
    freeze_inherited_heap()
    raise SystemExit(child_main(args))


if __name__ == "__main__":
    raise SystemExit(child_main(json.loads(Path(sys.argv[1]).read_text())))
