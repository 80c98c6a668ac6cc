"""A report (or the results page) whose inputs did not change is not built again.

`make bench` ends by rebuilding the three reports and the results page, most
often with nothing new in the stores. The figure cache
(:mod:`albot1.report.figure_cache`) spares the drawing, but importing the
plotting stack, collecting every cell, the paired comparisons, the thesis
verdicts, the tables and the pages still took about 46 s per re-run. So a
build is stamped as a whole: its stamp (:data:`STAMP`, in the folder it
writes) holds

* the digest of everything the build reads: the code version, the versions
  of the libraries that draw and tabulate, the project's TOML folders
  (:mod:`albot1.resources`, with ``ALBOT1_CONFIG_DIR``'s), the options, and
  the content (sha256) of every file of the folders it reads (the stores,
  with their companions);
* the size, modification and change times and inode of every file it wrote.

A build is skipped when the digest is the same and every recorded output is
still there with the same stat; otherwise it runs in full (its figures still
come from the figure cache when their own inputs did not change). Inputs are
judged by content, not by time: `albot1 bench` rewrites ``grid.json`` with
the same bytes on every run, and a copied store holds the same results. A
file's sha256 is remembered with its size, modification and change times and
inode, so a re-run reads only the files rewritten since (a rewrite of the
same size whose modification time was put back still changes the change
time). The folders read are the ones recorded by the last build: a changed
plan changes ``grid.json``'s digest, and the build that follows records the
folders anew.

This module imports nothing heavy: the check runs before the plotting stack
is imported (that import alone is seconds).
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from albot1 import versions
from albot1.atomic import atomic_write
from albot1.errors import ConfigError
from albot1.resources import FOLDERS, resource_dirs

#: The stamp file, in the folder a build writes.
STAMP = "build.json"
#: Bumped when the stamp's layout changes: a stamp of another version is not trusted.
STAMP_VERSION = 2  # 2: a file's stat holds its change time and inode
#: The libraries whose version can change what a report draws or tabulates.
LIBRARIES = ("numpy", "pandas", "scipy", "matplotlib", "plotly", "pydantic")
#: The stamp files of the figure cache (:data:`albot1.report.figure_cache.STAMPS`; not imported: it is heavy).
FIGURE_STAMPS = "figures.json"


@dataclass(frozen=True)
class Source:
    """Files a build reads: every file under ``root`` whose name matches ``pattern`` (hidden files left out)."""

    root: Path
    pattern: str = "*"

    def __post_init__(self) -> None:
        object.__setattr__(self, "root", Path(os.path.abspath(self.root)))  # the same folder from any working dir

    def files(self) -> list[Path]:
        """The matching files, sorted; none when ``root`` is absent (an absent companion is an input too)."""
        found: list[Path] = []
        for folder, dirs, names in os.walk(self.root):
            dirs[:] = [d for d in dirs if not d.startswith(".")]
            found += [Path(folder, n) for n in names if not n.startswith(".") and Path(n).match(self.pattern)]
        return sorted(found)

    def to_json(self) -> list[str]:
        return [str(self.root), self.pattern]


def _stat(path: Path) -> tuple[int, ...] | None:
    """What tells a file's rewrite without reading it: size, modification and change times, inode.

    The size and modification time alone miss a rewrite of the same size whose time was put back
    (``touch -r``, ``cp -p``, ``rsync -t`` of an edited file): the change time and the inode cannot be
    set back, so such a file is read again (a copied store is too: new inodes, same bytes, nothing rebuilt).
    """
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino)


#: Length of a remembered fingerprint: the :func:`_stat` fields, then the sha256.
_ENTRY = 5
#: Every sha256 this process worked out, by absolute path (same entries as :attr:`Fingerprints.known`): a
#: report's figure cache reads the run files its build stamp has just hashed (:func:`content_sha256`).
_SEEN: dict[str, list[Any]] = {}


class Fingerprints:
    """The sha256 of files, remembered with the :func:`_stat` they had when read."""

    def __init__(self, known: dict[str, Any] | None = None) -> None:
        self.known: dict[str, list[Any]] = {}
        for name, entry in (known or {}).items():
            if isinstance(entry, list) and len(entry) == _ENTRY:
                self.known[name] = entry
        self.read = 0  # files hashed (not found in memory): what a test and a timing can look at

    def sha256(self, path: Path) -> str:
        """``path``'s sha256 ("absent" when it cannot be read); read again only when its :func:`_stat` changed."""
        name = os.path.abspath(path)
        stat = _stat(path)
        if stat is not None:
            for memory in (self.known, _SEEN):
                entry = memory.get(name)
                if entry is not None and tuple(entry[:-1]) == stat:
                    self.known[name] = _SEEN[name] = entry
                    return str(entry[-1])
        try:
            digest = hashlib.sha256()
            with open(path, "rb") as handle:
                for block in iter(lambda: handle.read(1 << 20), b""):
                    digest.update(block)
        except OSError:
            return "absent"
        self.read += 1
        if stat is not None:
            self.known[name] = _SEEN[name] = [*stat, digest.hexdigest()]
        return digest.hexdigest()


def content_sha256(path: Path) -> str:
    """``path``'s sha256 ("absent" when it cannot be read), read only when this process has not already."""
    return Fingerprints().sha256(path)


def resources_digest() -> list[list[str]]:
    """(folder, file name, sha256) of the project's TOML files (datasets, methods, suites), as they are found."""
    parts: list[list[str]] = []
    for folder in FOLDERS:
        try:
            dirs = resource_dirs(folder)
        except ConfigError as exc:  # no such folder: the build would say so; its absence is the input
            parts.append([folder, "", str(exc)])
            continue
        for base in dirs:
            for path in sorted(base.glob("*.toml")):
                parts.append([folder, path.name, hashlib.sha256(path.read_bytes()).hexdigest()])
    return parts


class BuildStamp:
    """The stamp of one build's folder: is the last build still what a build would write, and record a build."""

    def __init__(self, folder: Path, name: str = STAMP) -> None:
        self.folder = folder
        self.path = folder / name
        stored = self._read()
        self._stored = stored
        self.fingerprints = Fingerprints(stored.get("inputs_sha256"))

    def _read(self) -> dict[str, Any]:
        try:
            data = json.loads(self.path.read_text(encoding="utf-8"))
        except (OSError, ValueError):  # absent or damaged: the build runs
            return {}
        if not isinstance(data, dict) or data.get("version") != STAMP_VERSION:
            return {}
        return data

    def digest(self, sources: Sequence[Source], options: dict[str, Any]) -> str:
        """The digest of a build reading ``sources`` with ``options`` (JSON-able) under this code and libraries."""
        parts = {
            "code": versions.code_version(),
            "libraries": versions.library_versions(LIBRARIES),
            "resources": resources_digest(),
            "options": options,
            "inputs": [
                [str(s.root), s.pattern, [[_relative(f, s.root), self.fingerprints.sha256(f)] for f in s.files()]]
                for s in sources
            ],
        }
        text = json.dumps(parts, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()

    def recorded_sources(self) -> list[Source] | None:
        """The sources the last build read (None when there is no usable stamp)."""
        stored = self._stored.get("sources")
        if not isinstance(stored, list):
            return None
        sources: list[Source] = []
        for entry in stored:
            if not (isinstance(entry, list) and len(entry) == 2 and all(isinstance(e, str) for e in entry)):
                return None
            sources.append(Source(Path(entry[0]), entry[1]))
        return sources

    def fresh(self, options: dict[str, Any]) -> Any | None:
        """The last build's payload when it is still what a build with ``options`` would write, else None.

        Fresh means: same digest over the sources the last build read, and
        every file it wrote still there with the same size and time.
        """
        sources = self.recorded_sources()
        outputs = self._stored.get("outputs")
        if sources is None or not isinstance(outputs, dict) or "payload" not in self._stored:
            return None
        if self.digest(sources, options) != self._stored.get("digest"):
            return None
        for name, stat in outputs.items():
            if not isinstance(stat, list) or _stat(self._path(name)) != tuple(stat):
                return None
        return self._stored["payload"]

    def forget(self) -> None:
        """Remove the stamp (before a build: a build that stops half-way leaves none)."""
        self.path.unlink(missing_ok=True)

    def record(self, sources: Sequence[Source], digest: str, outputs: Iterable[Path], payload: Any) -> None:
        """Stamp a finished build: what it read, its :meth:`digest` and the files it wrote (``payload``: JSON-able).

        The digest is taken before the build starts: a store changed while
        the build read it then leaves a stamp that the next check refuses.
        """
        written: dict[str, list[int]] = {}
        for path in outputs:
            stat = _stat(path)
            if stat is not None and path != self.path:
                written[self._name(path)] = list(stat)
        document = {
            "version": STAMP_VERSION,
            "digest": digest,
            "sources": [s.to_json() for s in sources],
            "outputs": dict(sorted(written.items())),
            "payload": payload,
            "inputs_sha256": self.fingerprints.known,
        }
        atomic_write(self.path, lambda tmp: tmp.write_text(json.dumps(document, sort_keys=True)))

    def _name(self, path: Path) -> str:
        try:
            return str(path.relative_to(self.folder))
        except ValueError:
            return os.path.abspath(path)

    def _path(self, name: str) -> Path:
        path = Path(name)
        return path if path.is_absolute() else self.folder / path


def _relative(path: Path, root: Path) -> str:
    try:
        return path.relative_to(root).as_posix()
    except ValueError:
        return path.as_posix()


def folder_files(folder: Path) -> list[Path]:
    """Every file under ``folder`` (what a report build leaves there: its outputs)."""
    return Source(folder).files()


def forget_all(folder: Path) -> None:
    """Trust no stamp under ``folder`` (``--force``): the build stamp and every figure cache's stamps go."""
    (folder / STAMP).unlink(missing_ok=True)
    for stamps in Source(folder, FIGURE_STAMPS).files():
        stamps.unlink(missing_ok=True)


def unsettled(folder: Path) -> bool:
    """Whether a figure cache under ``folder`` holds a group it could not keep (a drawing that failed)."""
    for stamps in Source(folder, FIGURE_STAMPS).files():
        try:
            data = json.loads(stamps.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return True
        if not isinstance(data, dict) or data.get("unsettled"):
            return True
    return False
