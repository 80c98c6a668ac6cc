"""Atomic file writes: a killed process leaves the old file or the new one, never half of one.

The content is written to a temporary file in the destination's folder (so the
final ``os.replace`` is a rename within one file system) and renamed over the
destination; on any error the temporary file is removed.
"""

from __future__ import annotations

import functools
import os
import tempfile
from collections.abc import Callable
from pathlib import Path


@functools.cache
def _umask() -> int:
    """The process's umask, read once (``/proc/self/status`` where it exists: no window with another mask)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def normal_mode() -> int:
    """The mode ``open()`` would give a new file (0o666 less the umask), for files made by ``mkstemp`` (0o600)."""
    return 0o666 & ~_umask()


def atomic_write(path: str | Path, writer: Callable[[Path], object]) -> None:
    """Call ``writer(tmp_path)`` and rename the result to ``path`` (``writer``'s return value is ignored).

    The temporary name keeps ``path``'s suffix, so writers that choose a
    compression or format by suffix (``.gz``, ``.npz``) behave as for ``path``.
    The file gets the permissions of a file made with ``open()`` (the
    temporary file of ``mkstemp`` is private to its owner). An ``OSError``
    about the temporary file (disk full, read-only folder) names ``path``.
    """
    dest = Path(path)
    try:
        fd, tmp = tempfile.mkstemp(dir=dest.parent, prefix=f".{dest.name}.", suffix=f".tmp{''.join(dest.suffixes)}")
    except OSError as exc:  # name the file the caller asked for, not the temporary one
        raise type(exc)(exc.errno, exc.strerror, str(dest)) from exc
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        writer(tmp_path)
        if tmp_path.is_file():
            os.chmod(tmp_path, normal_mode())
        os.replace(tmp_path, dest)
    except OSError as exc:
        if exc.errno is not None and exc.filename in (None, str(tmp_path)):
            raise type(exc)(exc.errno, exc.strerror, str(dest)) from exc
        raise
    finally:
        tmp_path.unlink(missing_ok=True)


def remove_temporaries(folder: str | Path) -> list[Path]:
    """Delete the temporary files :func:`atomic_write` left in ``folder`` when its process was killed mid-write.

    Only for a folder no other process is writing into (a run folder being
    rewritten, a bench cell's folder under the results lock): a live
    writer's temporary file would be taken from under it. Returns what was removed.
    """
    removed = []
    for path in Path(folder).glob(".*.tmp*"):
        if path.is_file():
            path.unlink(missing_ok=True)
            removed.append(path)
    return removed
