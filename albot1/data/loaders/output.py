"""Where a writer may create its output, and operating-system errors as one-line WriteErrors.

Every writer (CARMEN, albot log, ROS1, ROS2) and ``albot1 convert`` follow
one policy: the output must not exist; missing parent folders are created;
a parent that is a file, a folder that is not writable, a read-only file
system or a kernel pseudo-file system (``/proc``, ``/sys``) is refused
*before* anything is read or written, naming the path; an
``OSError`` while writing (disk full, permissions changed, ...) becomes a
:class:`~albot1.data.errors.WriteError` naming the path, never a traceback.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from albot1.data.errors import DataError, WriteError

_REASONS = {
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EROFS: "the file system is read-only",
    errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "the disk quota is exceeded",
    errno.ENOTDIR: "a folder on the way is a file",
    errno.ENOENT: "a folder on the way does not exist",
    errno.EEXIST: "it exists already",
    errno.EISDIR: "it is a folder",
}


def _reason(exc: OSError) -> str:
    return _REASONS.get(exc.errno or 0, exc.strerror or type(exc).__name__)


def _first_existing(path: Path) -> Path:
    """``path`` or its nearest ancestor that exists (a relative path ends at ``.``)."""
    current = path
    while not current.exists() and current != current.parent:
        current = current.parent
    return current


def check_output(path: str | Path) -> Path:
    """Refuse an output that cannot be created, without touching the disk (a WriteError naming it)."""
    out = Path(path)
    if out.exists() or out.is_symlink():
        raise WriteError(f"{out} exists already; remove it or choose another output path")
    parent = out.parent if str(out.parent) else Path(".")
    existing = _first_existing(parent.absolute())
    if not existing.is_dir():
        raise WriteError(f"{out}: cannot be created, {existing} is a file, not a folder")
    if _without_storage(existing):
        raise WriteError(f"{out}: cannot be created in {existing}: {NO_STORAGE}")
    if not os.access(existing, os.W_OK | os.X_OK):
        how = "the file system is read-only" if _read_only(existing) else "permission denied"
        raise WriteError(f"{out}: cannot be created in {existing}: {how}")
    return out


#: Why a folder of /proc or /sys cannot take an output, even for root (whom ``os.access`` always lets write).
NO_STORAGE = "it is on a kernel pseudo-file system (like /proc and /sys), where no file can be created"


def _read_only(folder: Path) -> bool:
    try:
        return bool(os.statvfs(folder).f_flag & os.ST_RDONLY)
    except OSError:
        return False


def _without_storage(folder: Path) -> bool:
    """A file system with neither blocks nor inodes (procfs, sysfs).

    Creating a file there fails (ENOENT) only once the writer opens it, after
    the whole input was read, and reads as "a folder on the way does not
    exist" though the folder exists; root passes ``os.access``, so the stat
    of the file system is what tells.
    """
    try:
        stats = os.statvfs(folder)
    except OSError:
        return False
    return stats.f_blocks == 0 and stats.f_files == 0


def prepare_output(path: str | Path) -> Path:
    """:func:`check_output`, then create the missing parent folders."""
    out = check_output(path)
    with writing(out):
        out.parent.mkdir(parents=True, exist_ok=True)
    return out


@contextmanager
def writing(path: Path) -> Iterator[None]:
    """Turn an ``OSError`` raised while writing ``path`` into one WriteError naming it.

    An error about another file (the input, read while writing) keeps its own
    file name, as a DataError.
    """
    try:
        yield
    except OSError as exc:
        named = Path(exc.filename).absolute() if isinstance(exc.filename, (str, Path)) else None
        out = Path(path).absolute()
        ours = named is None or named == out or named.parent == out.parent or out in named.parents
        if not ours and named not in out.parents:  # e.g. the input, read while writing
            raise DataError(f"{exc.filename}: {_reason(exc)}") from exc
        raise WriteError(f"{path}: cannot be written: {_reason(exc)}") from exc
