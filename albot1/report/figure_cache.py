"""Figures whose inputs did not change are not drawn again.

Drawing is nearly all of a report's time (matplotlib's layout and two file
formats per figure: 18 of 20 s on the quick suite), and `make bench` rebuilds
every report after every grid, most often with few or no new cells. Each
group of figures (one dataset's figures, one figure of the thesis page) is
stamped with a digest of everything it is drawn from: the code version (so a
change of the plotting code redraws everything), the versions of the
libraries that draw (another matplotlib lays a figure out otherwise), the
drawing options, and the bytes of every file of every run folder the group
reads (not only ``result.json`` and ``metrics.json``: a trajectory, map or
per-scan time file rewritten in place is drawn from as it now is, as a report
built afresh would). A group is drawn again when its digest differs, when any
file it made is missing, or when the stamp file cannot be read; a stamp is
never trusted beyond that. A group found out of date is struck from the stamp
file before it is drawn again, so a report stopped while drawing it (Ctrl-C,
a kill) leaves no stamp that could vouch for its half-redrawn files later
(after the inputs went back to what the old stamp names).

A figure that is no longer drawn (its data gone: a robustness figure once a
degradation's cells are removed, a dataset no longer in the store, another
store reported into the same folder) would stay in the folder with its old
numbers, unlinked but there to be copied into a paper. So a build's
:meth:`FigureCache.save` deletes the files of this folder that the stamps
named before and no group names now, and forgets the groups the build did
not look up: the folder holds what a report built afresh holds.

The stamps are one JSON file (:data:`STAMPS`) beside the figures, written
atomically once the figures are on disk. A group whose drawing could not be
kept (a figure that failed: its reason is worked out again next time) is
named in the stamps as unsettled, so that the report it belongs to is not
skipped as a whole next time (:mod:`albot1.report.build_stamp`).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from albot1 import versions
from albot1.atomic import atomic_write
from albot1.report.build_stamp import LIBRARIES, Source, content_sha256
from albot1.report.collect import CellRecord

#: The stamp file, in the folder of the figures it describes.
STAMPS = "figures.json"
#: Bumped when the stamp file's layout changes: stamps of another version are ignored.
STAMPS_VERSION = 1


def record_digest(record: CellRecord) -> list[str]:
    """What of a cell a figure can show: its key, status and the bytes of every file of its run folder.

    Every file, not a list of those the figures read today: a figure that starts reading another file of
    the run folder cannot be forgotten here. The build stamp has just hashed the same files
    (:func:`content_sha256` reads each once per process).
    """
    if record.status != "done":
        return [record.cell.key, record.status]
    folder = Source(record.run_dir)
    files = [[f.relative_to(folder.root).as_posix(), content_sha256(f)] for f in folder.files()]
    return [record.cell.key, record.status, json.dumps(files)]


def inputs_digest(records: Iterable[CellRecord], *options: object) -> str:
    """The digest of a group of figures: the code and drawing libraries' versions, ``options`` and ``records``."""
    parts = [
        versions.code_version(),
        versions.library_versions(LIBRARIES),
        [record_digest(r) for r in records],
        list(options),
    ]
    text = json.dumps(parts, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


@dataclass(frozen=True)
class Cached:
    """What a group of figures produced last time: the files it made and the caller's JSON-able ``payload``."""

    files: list[Path]
    payload: Any


class FigureCache:
    """The stamps of one folder of figures: look a group up before drawing it, store it after."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.stamps = folder / STAMPS
        self._groups: dict[str, dict[str, Any]] = self._read()
        self._changed = False
        self._unsettled: set[str] = set()
        self._was_unsettled = self._read_unsettled()
        self._named_before = self._names()
        self._seen: set[str] = set()  # the groups this build looked up, stored or could not keep
        self._kept: set[str] = set()  # files of groups it could not keep, drawn this time

    def _read(self) -> dict[str, dict[str, Any]]:
        try:
            data = json.loads(self.stamps.read_text(encoding="utf-8"))
        except (OSError, ValueError):  # absent or damaged: every group is drawn again
            return {}
        if not isinstance(data, dict) or data.get("version") != STAMPS_VERSION:
            return {}
        groups = data.get("groups")
        if not isinstance(groups, dict):
            return {}
        return {k: v for k, v in groups.items() if isinstance(v, dict)}

    def _names(self) -> set[str]:
        """Every file the stamps name (the groups' files, as stored)."""
        return {f for entry in self._groups.values() for f in entry.get("files") or [] if isinstance(f, str)}

    def _read_unsettled(self) -> set[str]:
        try:
            data = json.loads(self.stamps.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return set()
        found = data.get("unsettled") if isinstance(data, dict) else None
        return {str(g) for g in found} if isinstance(found, list) else set()

    def name(self, path: Path) -> str:
        """How a file is stored: relative to the folder when inside it (the report can move), else absolute."""
        try:
            return str(path.relative_to(self.folder))
        except ValueError:
            return str(path.resolve())

    def path(self, stored: str) -> Path:
        """The file a stored name stands for (:meth:`name`'s inverse)."""
        path = Path(stored)
        return path if path.is_absolute() else self.folder / path

    def lookup(self, group: str, digest: str) -> Cached | None:
        """The group's files and payload when its digest is ``digest`` and every file it made still exists."""
        self._seen.add(group)
        entry = self._groups.get(group)
        if entry is not None and entry.get("digest") != digest:
            self._strike(group)
            return None
        if entry is None:
            return None
        stored = entry.get("files")
        if not isinstance(stored, list) or not all(isinstance(f, str) for f in stored):
            return None
        files = [self.path(f) for f in stored]
        if not all(f.is_file() for f in files):
            return None
        return Cached(files, entry.get("payload"))

    def _strike(self, group: str) -> None:
        """Forget an out-of-date ``group`` on disk at once: it is about to be drawn again, and may be stopped."""
        self._groups.pop(group, None)
        self._changed = True
        self._write(self._unsettled | self._was_unsettled)  # the stamps' own save still follows

    def store(self, group: str, digest: str, files: Iterable[Path], payload: Any = None) -> None:
        """Remember that ``group`` drawn from ``digest`` made ``files`` (and their vector twins where they exist)."""
        self._groups[group] = {"digest": digest, "files": self._stored_names(files), "payload": payload}
        self._seen.add(group)
        self._unsettled.discard(group)
        self._changed = True

    def _stored_names(self, files: Iterable[Path]) -> list[str]:
        """The stored names of ``files`` and of their vector twins, those that exist."""
        names = {self.name(path) for f in files for path in (f, f.with_suffix(".svg")) if path.is_file()}
        return sorted(names)

    def unsettled(self, group: str, files: Iterable[Path] = ()) -> None:
        """Say that ``group`` was drawn but could not be kept (a failed drawing): the next build must try again.

        ``files``: what the drawing made all the same (the page links them): they are not deleted as stale.
        """
        self._kept.update(self._stored_names(files))
        self._groups.pop(group, None)
        self._seen.add(group)
        self._unsettled.add(group)

    def save(self) -> None:
        """Write the stamps (atomically) when a group was stored or the unsettled groups changed since read.

        Called once a build has looked up every group it draws: the groups it did not are forgotten, and the
        files of this folder that only earlier drawings named are deleted (see the module docstring).
        """
        for group in set(self._groups) - self._seen:
            del self._groups[group]
            self._changed = True
        for stale in self._named_before - self._names() - self._kept:
            if not Path(stale).is_absolute():  # a file of another folder (a thesis figure's link) is not ours
                self.path(stale).unlink(missing_ok=True)
        self._named_before = self._names()
        if not self._changed and self._unsettled == self._was_unsettled:
            return
        self._write(self._unsettled)
        self._changed = False
        self._was_unsettled = set(self._unsettled)

    def _write(self, unsettled: set[str]) -> None:
        document = {"version": STAMPS_VERSION, "groups": self._groups, "unsettled": sorted(unsettled)}
        atomic_write(self.stamps, lambda tmp: tmp.write_text(json.dumps(document, indent=1, sort_keys=True)))


def clear_figures(folder: Path) -> None:
    """A build without figures (``--no-plots``) into ``folder``: delete what an earlier build drew and stamped there.

    Left in place, those figures would show an earlier build's numbers beside this build's tables, unlinked but
    there to be copied into a paper (the same reason :meth:`FigureCache.save` deletes figures no longer drawn).
    Only files the stamps name are deleted: anything else in the folder is not the report's and stays.
    """
    if (folder / STAMPS).is_file():
        FigureCache(folder).save()  # no group looked up: every stamped group is forgotten and its files deleted
