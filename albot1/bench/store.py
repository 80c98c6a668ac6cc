"""The results store: ``results/<suite>/`` with one folder per cell.

Layout::

    results/<suite>/
        grid.json              the plan of the last `albot1 bench` (cells, skipped, machine)
        suite.toml             a copy of the suite file that made it
        .lock                  held while a runner works here (flock: released even on SIGKILL)
        runs/<key>/            the run folder (albot1.runs.folder) plus:
            cell.json          the cell that made it
            metrics.json       written by albot1.runs.evaluate
            cell.log           the child process's output (tracebacks included)
            attempt.json       wall time of the successful attempt (run + store + evaluation)
            FAILED.json        only after a failure: reason, kind, exit code, elapsed

A cell is complete when its run folder has ``DONE`` and a ``metrics.json``
that parses: both are written by atomic rename, so a runner killed at any
instant leaves cells that are either complete or recomputed on the next run,
never half-read. ``FAILED.json`` is removed before a retry and never
coexists with a completed result after one.
"""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import socket
import time
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from albot1.atomic import atomic_write
from albot1.bench.errors import BenchError
from albot1.bench.grid import Cell, FailureKind, GridPlan
from albot1.runs.folder import is_complete as run_is_complete
from albot1.runs.folder import write_json

FAILED = "FAILED.json"
CELL = "cell.json"
LOG = "cell.log"
METRICS = "metrics.json"
PLAN = "grid.json"
ATTEMPT = "attempt.json"


@dataclass(frozen=True)
class Failure:
    """A stored failure record."""

    reason: str
    kind: str
    exit_code: int | None
    elapsed_s: float
    log: str | None


class ResultsStore:
    """One suite's results folder."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)
        self.runs = self.root / "runs"
        self._lock_file: IO[str] | None = None

    # -- the grid ---------------------------------------------------------
    def write_plan(self, plan: GridPlan, suite_file: Path | None = None) -> None:
        self.runs.mkdir(parents=True, exist_ok=True)
        write_json(self.root / PLAN, plan.to_json())
        if suite_file is not None and suite_file.is_file():
            atomic_write(self.root / "suite.toml", lambda tmp: shutil.copyfile(suite_file, tmp))

    def read_plan(self) -> GridPlan:
        path = self.root / PLAN
        if not path.is_file():
            raise BenchError(
                f"{self.root}: not a results folder of `albot1 bench` (no {PLAN}); run `albot1 bench SUITE` first"
            )
        try:
            return GridPlan.from_json(json.loads(path.read_text()))
        except (json.JSONDecodeError, KeyError, TypeError) as exc:
            raise BenchError(f"{path}: not a grid plan written by `albot1 bench`: {exc}") from None

    # -- locking ----------------------------------------------------------
    def lock(self) -> None:
        """Take the folder's lock; BenchError if another runner holds it."""
        self.root.mkdir(parents=True, exist_ok=True)
        handle = open(self.root / ".lock", "a+")
        try:
            fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.close()
            raise BenchError(f"{self.root}: another `albot1 bench` is running on this results folder") from None
        handle.seek(0)
        handle.truncate()
        handle.write(f"{socket.gethostname()} pid {os.getpid()}\n")
        handle.flush()
        self._lock_file = handle

    def unlock(self) -> None:
        if self._lock_file is not None:
            fcntl.flock(self._lock_file.fileno(), fcntl.LOCK_UN)
            self._lock_file.close()
            self._lock_file = None

    # -- cells ------------------------------------------------------------
    def run_dir(self, key: str) -> Path:
        return self.runs / key

    def is_complete(self, key: str) -> bool:
        """DONE marker plus a metrics.json that parses."""
        run_dir = self.run_dir(key)
        if not run_is_complete(run_dir):
            return False
        try:
            json.loads((run_dir / METRICS).read_text())
        except (OSError, json.JSONDecodeError):
            return False
        return True

    def prepare(self, cell: Cell) -> Path:
        """Make the cell's folder ready for an attempt: cell.json written, old failure and log removed."""
        run_dir = self.run_dir(cell.key)
        run_dir.mkdir(parents=True, exist_ok=True)
        (run_dir / FAILED).unlink(missing_ok=True)
        write_json(run_dir / CELL, cell.to_json())
        (run_dir / LOG).write_text(
            f"albot1 bench: {cell.describe()}, attempt started {time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())}\n",
            encoding="utf-8",
        )
        return run_dir

    def record_failure(
        self,
        cell: Cell,
        reason: str,
        kind: FailureKind,
        *,
        exit_code: int | None = None,
        elapsed_s: float = 0.0,
        traceback_text: str | None = None,
    ) -> None:
        """Write FAILED.json (and append a traceback to the cell log) for ``cell``."""
        run_dir = self.run_dir(cell.key)
        run_dir.mkdir(parents=True, exist_ok=True)
        log = run_dir / LOG
        if traceback_text:
            with log.open("a", encoding="utf-8") as handle:
                handle.write(f"\n--- albot1 bench: {kind} ---\n{traceback_text}\n")
        write_json(run_dir / CELL, cell.to_json())
        write_json(
            run_dir / FAILED,
            {
                "key": cell.key,
                "cell": cell.describe(),
                "reason": reason,
                "kind": kind,
                "exit_code": exit_code,
                "elapsed_s": elapsed_s,
                "log": LOG if log.is_file() else None,
                "time": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                "host": socket.gethostname(),
                "description": cell.to_json(),
            },
        )

    def failure(self, key: str) -> Failure | None:
        path = self.run_dir(key) / FAILED
        if not path.is_file():
            return None
        try:
            data = json.loads(path.read_text())
        except json.JSONDecodeError:
            return Failure("unreadable FAILED.json", "exception", None, 0.0, None)
        return Failure(
            str(data.get("reason")),
            str(data.get("kind")),
            data.get("exit_code"),
            float(data.get("elapsed_s") or 0.0),
            data.get("log"),
        )

    def read_json(self, key: str, name: str) -> dict[str, Any] | None:
        path = self.run_dir(key) / name
        try:
            return json.loads(path.read_text())
        except (OSError, json.JSONDecodeError):
            return None
