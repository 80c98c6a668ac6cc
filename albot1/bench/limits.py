"""Run one cell in a fresh child process under a time and memory limit.

Why a fresh process per cell: a timeout can only be enforced by killing, a
memory cap (``RLIMIT_AS``) is per process, a segfault in a C++ library must
not take the runner down, and ``peak_mb`` (``ru_maxrss``) is only the
cell's own peak in a process of its own.

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
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from albot1.bench.cell_main import process_entry
from albot1.bench.grid import Cell
from albot1.runs.folder import write_json

PRELOAD = ["__main__", "albot1.bench.preload"]
_FORKSERVER: Any = None


@dataclass(frozen=True)
class ChildExit:
    """How the child ended: its exit code (negative = killed by that signal) or a timeout."""

    exit_code: int | None
    timed_out: bool
    elapsed_s: float


def _forkserver() -> Any:
    global _FORKSERVER
    if _FORKSERVER is None:
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(PRELOAD)
        _FORKSERVER = ctx
    return _FORKSERVER


def start_forkserver() -> None:
    """Start the cell forkserver now (it computes the code version first thing, then imports).

    The runner calls this before planning, so that the code version its
    cells are forked with and the one the plan's keys use are taken moments
    apart rather than a planning pass apart.
    """
    if launcher() == "forkserver":
        from multiprocessing import forkserver

        _forkserver()
        forkserver.ensure_running()


def launcher() -> str:
    """``forkserver`` where this process may start children, else ``subprocess``."""
    if sys.platform.startswith("linux") and not multiprocessing.current_process().daemon:
        return "forkserver"
    return "subprocess"


def child_args(cell: Cell, runs_root: Path, log_path: Path, preview: str | None = None) -> dict[str, Any]:
    env = {k: v for k, v in os.environ.items() if k.startswith("ALBOT1_")}
    return {
        "cell": cell.to_json(),
        "runs_root": str(runs_root),
        "log_path": str(log_path),
        "preview": preview,
        "parent_pid": os.getpid(),
        "env": env,
    }


def run_limited(
    cell: Cell, runs_root: Path, log_path: Path, *, how: str | None = None, preview: str | None = None
) -> ChildExit:
    """Run ``cell`` in a child; kill it after ``cell.time_s`` seconds.

    ``preview`` is the ``module:function`` of the run preview renderer (``bench.cells.renderer_target``).
    """
    args = child_args(cell, runs_root, log_path, preview)
    start = time.monotonic()
    if (how or launcher()) == "forkserver":
        # The forkserver, not this process, is the child's parent; it exits when this process dies.
        args["parent_pid"] = None
        proc = _forkserver().Process(target=process_entry, args=(args,), name=f"cell-{cell.key}", daemon=False)
        proc.start()
        proc.join(cell.time_s)
        if proc.is_alive():
            proc.kill()
            proc.join()
            return ChildExit(None, True, time.monotonic() - start)
        return ChildExit(proc.exitcode, False, time.monotonic() - start)
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
        try:
            code = child.wait(timeout=cell.time_s)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()
            return ChildExit(None, True, time.monotonic() - start)
    args_file.unlink(missing_ok=True)
    return ChildExit(code, False, time.monotonic() - start)
