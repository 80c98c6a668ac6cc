"""Atomic file writes: a killed process leaves the old file or the new one, never half of one.

The content is written to a temporary file in the destination's folder (so the
final ``os.replace`` is a rename within one file system) and renamed over the
destination; on any error the temporary file is removed.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path


def atomic_write(path: str | Path, writer: Callable[[Path], object]) -> None:
    """Call ``writer(tmp_path)`` and rename the result to ``path`` (``writer``'s return value is ignored).

    The temporary name keeps ``path``'s suffix, so writers that choose a
    compression or format by suffix (``.gz``, ``.npz``) behave as for ``path``.
    """
    dest = Path(path)
    fd, tmp = tempfile.mkstemp(dir=dest.parent, prefix=f".{dest.name}.", suffix=f".tmp{''.join(dest.suffixes)}")
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        writer(tmp_path)
        os.replace(tmp_path, dest)
    finally:
        tmp_path.unlink(missing_ok=True)
