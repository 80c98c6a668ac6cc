"""What kind of thing a path names, checked before anything reads it.

A log, a relations file or a manifest is read from a *regular file* (or, for
a ROS2 bag, a folder). Anything else is refused up front, by its ``stat``
alone (:mod:`albot1.filetypes`), because reading it would hang (a FIFO blocks until a writer comes, a
socket cannot be opened), never end (``/dev/zero``, ``/dev/urandom``) or read
what is no data set at all (``/proc/self/environ``: a kernel pseudo-file that
reports 0 bytes and yet has content). Error messages describe a file's
content by its kind ("text, 3 lines", "binary"), never by quoting it: a user
pointed at the wrong file must not have that file's secrets printed back.
"""

from __future__ import annotations

import os
from pathlib import Path

from albot1.data.errors import DataError
from albot1.filetypes import kind_of


def check_input(path: Path, expected: str, *, folder_ok: bool = False) -> os.stat_result:
    """The ``stat`` of ``path`` when it is a regular file (or a folder, with ``folder_ok``); DataError otherwise.

    ``expected`` says what the caller wanted ("a log file or a ROS2 bag
    folder") and ends the one-line error. A missing path is a DataError
    too; callers that have their own message for it check existence first.
    """
    try:
        st = path.stat()
    except FileNotFoundError:
        raise DataError(f"{path}: no such file or directory; expected {expected}") from None
    except (OSError, ValueError) as exc:  # a name too long, a NUL, a permission problem on a parent folder
        shown = str(path) if len(str(path)) <= 200 else f"{str(path)[:200]}..."
        raise DataError(
            f"{shown}: not a usable path ({getattr(exc, 'strerror', None) or exc}); expected {expected}"
        ) from None
    kind = kind_of(path, st, folder_ok=folder_ok)
    if kind is not None:
        raise DataError(f"{path}: {kind}, not a regular file; expected {expected}")
    return st


def content_kind(head: bytes) -> str:
    """``"binary"`` (NUL bytes, control characters, not UTF-8) or ``"text"``, from a file's first bytes."""
    sample = head[:4096]
    if b"\0" in sample or sum(b < 9 or 13 < b < 32 for b in sample) > len(sample) // 10:
        return "binary"
    try:
        sample.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(sample) - 4:  # not just a character cut at the end of the sample
            return "binary"
    return "text"


def describe_content(head: bytes, *, lines: int | None = None) -> str:
    """``"binary"`` or ``"text, 3 lines"``: what a file holds, said without quoting any of it.

    ``head`` is the file's first bytes; ``lines`` the number of lines when the
    caller counted them (else the lines in ``head``, as "at least").
    """
    if content_kind(head) == "binary":
        return "binary"
    if lines is None:
        counted = head.count(b"\n") + (0 if head.endswith(b"\n") or not head else 1)
        return f"text, {counted} line{'s' if counted != 1 else ''} or more"
    return f"text, {lines} line{'s' if lines != 1 else ''}"
