"""The results store's own files read back through typed records: ``grid.json`` and ``FAILED.json``.

These files are written by the runner but live in a folder a user may edit,
copy or receive from someone else, so reading them trusts nothing: every
field is checked against its type (the :class:`~albot1.bench.grid.GridPlan`
and :class:`~albot1.bench.grid.Cell` dataclasses themselves, through
pydantic, so a field added there is checked here too) and a problem is one
:class:`~albot1.records.RecordError` naming the file and the field
(``grid.json: cells.0.seed: Input should be a valid integer``). A cell key
becomes a folder name under ``runs/``, so it must have the form
:func:`albot1.runs.folder.run_key` gives it (16 hex digits): a key such as
``../../../../etc`` is refused, never joined to a path.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from pydantic import NonNegativeFloat, TypeAdapter, ValidationError, field_validator

from albot1.bench.grid import FailureKind, GridPlan
from albot1.config.validation import describe_errors
from albot1.filetypes import not_regular
from albot1.records import Record, RecordError

#: What :func:`albot1.runs.folder.run_key` produces: the only cell keys a results folder may hold.
KEY_PATTERN = re.compile(r"[0-9a-f]{16}")

_PLAN = TypeAdapter(GridPlan)


class FailureRecord(Record):
    """``FAILED.json``: why a cell failed (see :meth:`albot1.bench.store.ResultsStore.record_failure`)."""

    reason: str
    kind: FailureKind
    exit_code: int | None = None
    elapsed_s: NonNegativeFloat = 0.0
    #: the time spent starting the cell's process before ``elapsed_s`` began (absent when unknown)
    launch_s: NonNegativeFloat | None = None
    log: str | None = None
    key: str | None = None
    cell: str | None = None
    time: str | None = None
    host: str | None = None
    description: dict[str, Any] | None = None

    @field_validator("log")
    @classmethod
    def _plain_name(cls, value: str | None) -> str | None:
        """The log is a file of the cell's own folder: a path elsewhere (``../../etc/passwd``) is refused."""
        if value is not None and (not value or Path(value).name != value or value in (".", "..")):
            raise ValueError(f"{value[:40]!r} is not a file name of the cell's folder (expected e.g. 'cell.log')")
        return value


def read_json_file(path: Path, what: str) -> Any:
    """The JSON value of ``path``; RecordError naming the file when it cannot be read or parsed."""
    problem = not_regular(path)
    if problem is not None:
        raise RecordError(f"{path}: {problem}; expected a {what}")
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RecordError(f"{path}: not a {what}: {exc}") from None


def parse_plan(data: Any, path: Path) -> GridPlan:
    """``grid.json``'s content as a GridPlan; RecordError naming ``path`` and the field."""
    if not isinstance(data, dict):
        raise RecordError(f"{path}: not a grid plan written by `albot1 bench`: expected a JSON object")
    try:
        plan = _PLAN.validate_python(data)
    except ValidationError as exc:
        raise RecordError(f"{path}: not a grid plan written by `albot1 bench`: {describe_errors(exc)}") from None
    for index, cell in enumerate(plan.cells):
        check_key(cell.key, f"{path}: cells.{index}.key")
    for key in plan.config_failures:
        check_key(key, f"{path}: config_failures")
    return plan


def check_key(key: str, where: str) -> str:
    """``key`` when it has the form of a cell key (16 hex digits); RecordError naming ``where`` otherwise."""
    if not KEY_PATTERN.fullmatch(key):
        shown = key if len(key) <= 40 else f"{key[:40]}..."
        raise RecordError(f"{where}: {shown!r} is not a cell key; expected 16 hex digits (a run folder name)")
    return key


def parse_failure(data: Any, path: Path) -> FailureRecord:
    """``FAILED.json``'s content; RecordError naming ``path`` and the field."""
    try:
        return FailureRecord.model_validate(data)
    except ValidationError as exc:
        raise RecordError(f"{path}: not a failure record written by `albot1 bench`: {describe_errors(exc)}") from None
