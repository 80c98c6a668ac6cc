"""The folders commands write into (``albot1 run --out``, ``albot1 bench --results``, ``albot1 report --out``).

A run root is reused from run to run (folders are named by content hash),
so unlike a converter's output it may exist. What is checked, before any
work: the path is a folder or can be made one, and a file can be created in
it (permissions, a read-only file system). Otherwise one line names the
option, the path, what was found and what was expected.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from albot1.runs.errors import OutputFolderError

EXPECTED = "expected a folder this user can write to (it is made when missing)"


def _nearest_existing(path: Path) -> Path:
    current = path.absolute()
    while not (current.exists() or current.is_symlink()) and current != current.parent:
        current = current.parent
    return current


def writable_folder(path: str | Path, option: str) -> Path:
    """Make ``path`` (and its parents) a folder and check a file can be created in it; returns ``path``.

    ``option`` names where the path came from in the message (``--out``).
    """
    folder = Path(path)
    existing = _nearest_existing(folder)
    if not existing.is_dir():
        found = "is a file" if existing == folder.absolute() else f"cannot be made: {existing} is a file"
        raise OutputFolderError(f"{option} {folder}: {found}, not a folder; {EXPECTED}")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):  # proves a file can be created there
            pass
    except OSError as exc:
        what = (exc.strerror or type(exc).__name__).lower()
        raise OutputFolderError(f"{option} {folder}: cannot write there: {what}; {EXPECTED}") from None
    return folder
