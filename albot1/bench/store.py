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

A cell is complete when its run folder has ``DONE``, a ``metrics.json``
that parses and a ``result.json`` of that very cell (its key): all are
written by atomic rename, so a runner killed at any instant leaves cells
that are either complete or recomputed on the next run, never half-read.
``FAILED.json`` is removed before a retry and never coexists with a
completed result after one.

A full or read-only file system is a failure of the grid, not of one cell:
the cell that met it is recorded as failed (kind ``storage``) after the
files of its failed attempt are deleted to make room for the record, and
the runner starts no further cell. Complete cells are never touched.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import shutil
import socket
import time
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from albot1.atomic import atomic_write, remove_temporaries
from albot1.bench.cell_main import ERROR_FILE
from albot1.bench.errors import BenchError
from albot1.bench.grid import Cell, FailureKind, GridPlan
from albot1.bench.store_records import parse_failure, parse_plan, read_json_file
from albot1.filetypes import not_regular
from albot1.records import RecordError, ResultRecord, read_record
from albot1.runs.folder import DONE, RESULT_FILE, write_json
from albot1.runs.folder import is_complete as run_is_complete

FAILED = "FAILED.json"
CELL = "cell.json"
LOG = "cell.log"
METRICS = "metrics.json"
PLAN = "grid.json"
ATTEMPT = "attempt.json"
#: The reason of a ``FAILED.json`` that cannot be parsed (such a record is never trusted to skip a cell).
UNREADABLE_FAILURE = "unreadable FAILED.json"


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
        if not path.exists():
            # what the user named is said first: a typo ("does not exist") is not a folder missing its grid
            if not self.root.exists():
                found = "does not exist; expected a results folder of `albot1 bench`"
            elif self.root.is_file():
                found = "is a file, not a results folder of `albot1 bench`"
            elif not self.root.is_dir():
                found = "is not a folder; expected a results folder of `albot1 bench`"
            else:
                found = f"not a results folder of `albot1 bench` (no {PLAN})"
            raise BenchError(f"{self.root}: {found}; run `albot1 bench SUITE` first")
        return parse_plan(read_json_file(path, "grid plan written by `albot1 bench`"), path)

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
        try:
            handle.seek(0)
            handle.truncate()
            handle.write(f"{socket.gethostname()} pid {os.getpid()}\n")
            handle.flush()
        except OSError as exc:  # a full or read-only disk: say which file (a bare write error names none)
            with contextlib.suppress(OSError):  # closing flushes the unwritten line again
                handle.close()
            raise type(exc)(exc.errno, exc.strerror, str(self.root / ".lock")) from None
        self._lock_file = handle

    def unlock(self) -> None:
        if self._lock_file is not None:
            fcntl.flock(self._lock_file.fileno(), fcntl.LOCK_UN)
            self._lock_file.close()
            self._lock_file = None

    # -- cells ------------------------------------------------------------
    def run_dir(self, key: str) -> Path:
        """``runs/<key>``; BenchError for a key that is not one plain folder name (it would lead elsewhere)."""
        if not key or key in (".", "..") or "/" in key or "\\" in key or "\0" in key:
            raise BenchError(f"{self.root}: cell key {key[:40]!r} is not a folder name; expected 16 hex digits")
        return self.runs / key

    def is_complete(self, key: str) -> bool:
        """DONE marker, a metrics.json that parses and a result.json of this very cell (:meth:`damage`)."""
        run_dir = self.run_dir(key)
        metrics = run_dir / METRICS
        if not run_is_complete(run_dir) or not_regular(metrics) is not None or not metrics.is_file():
            return False  # a FIFO or device in place of metrics.json is no result (and reading it would hang)
        return self.damage(key) is None

    def read_result(self, key: str) -> ResultRecord:
        """The ``result.json`` of ``runs/<key>``; RecordError (one line naming the file) when it is no run of ``key``.

        A run folder is named by the hash of what it ran, so a ``result.json``
        naming another key is a folder copied or renamed by hand: its numbers
        belong to another cell and must not be read as this one's.
        """
        path = self.run_dir(key) / RESULT_FILE
        result = read_record(ResultRecord, path)
        if result.key != key:
            raise RecordError(
                f"{path}: holds the run of cell {result.key[:40]!r}, not of {key}, the folder's name "
                "(a run folder copied or renamed?)"
            )
        return result

    def damage(self, key: str) -> str | None:
        """Why the run folder of ``key``, marked DONE, is no readable run of that cell (one line naming the file).

        None when it is one, and for a folder without DONE or without
        ``metrics.json`` (a run stopped before it ended or before its
        evaluation: the next attempt completes it). A damaged folder (a
        truncated or edited ``result.json`` or ``metrics.json``, another
        cell's files) used to be kept by the bench as complete when only its
        ``result.json`` was damaged, and the report then failed on it at every
        build, or read another cell's numbers under this cell's name.
        """
        run_dir = self.run_dir(key)
        if not run_is_complete(run_dir):
            return None
        try:
            self.read_result(key)
            metrics = run_dir / METRICS
            if metrics.exists() or metrics.is_symlink():
                read_json_file(metrics, "metrics record written by `albot1 evaluate`")
        except RecordError as exc:
            return str(exc)
        return None

    def prepare(self, cell: Cell) -> Path:
        """Make the cell's folder ready for an attempt: cell.json written, old failure, log and temporaries removed.

        Temporary files of writers killed in an earlier attempt (a timeout, a
        SIGKILLed runner) would otherwise stay in the completed folder. A
        folder marked DONE whose ``result.json`` is no run of this cell
        (:meth:`read_result`) loses its DONE, so the cell runs again rather
        than only being evaluated again.
        """
        run_dir = self.run_dir(cell.key)
        run_dir.mkdir(parents=True, exist_ok=True)
        if run_is_complete(run_dir):
            try:
                self.read_result(cell.key)
            except RecordError:  # DONE over no run of this cell: run it again, not only evaluate what is there
                (run_dir / DONE).unlink(missing_ok=True)
        (run_dir / FAILED).unlink(missing_ok=True)
        (run_dir / ERROR_FILE).unlink(missing_ok=True)
        remove_temporaries(run_dir)
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
        launch_s: float | None = None,
        traceback_text: str | None = None,
    ) -> str | None:
        """Write FAILED.json (and append a traceback to the cell log) for ``cell``.

        ``elapsed_s``: the cell's wall time from the moment its process existed; ``launch_s``: the time spent
        starting that process (the forkserver's preload when the cell waited for it), when known.

        Never raises for the file system: returns None when the record was
        written, else why it could not be (the caller still reports the
        failure). For a ``storage`` failure the files of the cell's attempt
        are deleted first, so that the small record fits where the run did not.
        """
        run_dir = self.run_dir(cell.key)
        log = run_dir / LOG
        try:
            run_dir.mkdir(parents=True, exist_ok=True)
            if kind == "storage" and not self.is_complete(cell.key):
                discard_attempt(run_dir)
            if traceback_text:
                with log.open("a", encoding="utf-8") as handle:
                    handle.write(f"\n--- albot1 bench: {kind} ---\n{traceback_text}\n")
        except OSError:
            pass  # the log is a courtesy; FAILED.json below is the record
        try:
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
                    **({} if launch_s is None else {"launch_s": launch_s}),
                    "log": LOG if log.is_file() else None,
                    "time": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                    "host": socket.gethostname(),
                    "description": cell.to_json(),
                },
            )
        except OSError as exc:
            return f"{run_dir / FAILED}: cannot be written: {exc.strerror or exc}"
        return None

    def failure(self, key: str, *, strict: bool = True) -> Failure | None:
        """The cell's ``FAILED.json``, None when there is none.

        A record that cannot be read or does not fit :class:`FailureRecord`
        is a RecordError naming the file and the field; with ``strict=False``
        (the runner, which is about to retry the cell) it is a failure whose
        reason is :data:`UNREADABLE_FAILURE`, never trusted to skip the cell.
        """
        path = self.run_dir(key) / FAILED
        if not path.is_file():
            return None
        try:
            record = parse_failure(read_json_file(path, "failure record written by `albot1 bench`"), path)
        except RecordError:
            if strict:
                raise
            return Failure(UNREADABLE_FAILURE, "exception", None, 0.0, None)
        return Failure(record.reason, record.kind, record.exit_code, record.elapsed_s, record.log)

    def read_json(self, key: str, name: str) -> dict[str, Any] | None:
        path = self.run_dir(key) / name
        try:
            loaded: dict[str, Any] | None = json.loads(path.read_text())
            return loaded
        except (OSError, json.JSONDecodeError):
            return None


def discard_attempt(run_dir: Path) -> None:
    """Delete the files of a cell's failed attempt, keeping ``cell.json`` and ``cell.log``.

    Only for a cell that is not complete (no ``DONE`` plus ``metrics.json``):
    its next attempt recomputes them anyway, and deleting them frees the
    space a full disk needs for the failure record.
    """
    for path in run_dir.iterdir():
        if path.name not in (CELL, LOG) and (path.is_file() or path.is_symlink()):
            path.unlink(missing_ok=True)
