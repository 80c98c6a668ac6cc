"""What a path is, by its ``stat`` alone: the one test every reader of an input file runs first.

A regular file can be read to its end; a FIFO blocks until a writer comes, a
socket cannot be opened, ``/dev/zero`` never ends, and a kernel pseudo-file
(``/proc/self/environ``) reports 0 bytes yet has content. Readers in every
layer (data files, the JSON records of a run, the results store) refuse
such paths up front with their own error class, using :func:`not_regular`.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

#: ``stat`` predicates of the file types that are neither regular files nor folders, with their names.
_SPECIAL = (
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)
PSEUDO_FILE = "a kernel pseudo-file (it reports 0 bytes yet has content, like the files under /proc and /sys)"


def special_kind(mode: int) -> str | None:
    """The name of a non-regular, non-folder file type (``"a FIFO (named pipe)"``), None otherwise."""
    return next((name for test, name in _SPECIAL if test(mode)), None)


def is_pseudo_file(path: Path, st: os.stat_result) -> bool:
    """A regular file whose size is 0 and yet can be read (``/proc``, ``/sys``): its size says nothing."""
    if not stat.S_ISREG(st.st_mode) or st.st_size != 0:
        return False
    try:
        with path.open("rb") as handle:
            return handle.read(1) != b""
    except OSError:
        return False


def kind_of(path: Path, st: os.stat_result, *, folder_ok: bool = False) -> str | None:
    """What ``path`` is when it is not a readable regular file (or a folder, with ``folder_ok``); None when it is."""
    kind = special_kind(st.st_mode)
    if kind is None and stat.S_ISDIR(st.st_mode) and not folder_ok:
        kind = "a folder"
    if kind is None and is_pseudo_file(path, st):
        kind = PSEUDO_FILE
    return kind


def not_regular(path: Path) -> str | None:
    """``"a FIFO (named pipe), not a regular file"`` for an existing path that is no regular file; None otherwise.

    A missing path is None: each caller has its own words for it.
    """
    try:
        st = path.stat()
    except (OSError, ValueError):
        return None
    kind = kind_of(path, st)
    return f"{kind}, not a regular file" if kind is not None else None
