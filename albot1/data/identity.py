"""The content identity of data files: their sha256, computed once and cached by what ``stat`` says.

A result must name the data it was computed from, not just the data's name:
a log edited after its benchmark cell ran must give a new cell key, and a
catalog file must be the one its manifest's checksum names. Hashing a
100 MB log on every command would cost seconds, so the checksum of a file is
cached under its resolved path together with its size, ``mtime_ns``,
``ctime_ns``, inode and device; a file whose ``stat`` still matches is not read again (a warm
check costs a ``stat`` and a small JSON read; ``docs/datasets.md``,
"Checksums"). Anything else in ``stat`` changed -- an edit, a copy, a
``touch`` -- and the file is hashed again. The change time is part of the
key because no user can set it: an edit that puts the old modification
time back (``touch -r``, ``rsync --times``, a tool restoring stamps) still
changes it, so a flipped byte is never taken for the verified content.

The cache (:func:`albot1.settings.checksum_cache_file`) is a convenience
and never trusted beyond that: a cache that does not parse, or an entry of
the wrong shape or whose seal (a digest over its fields) does not match, is
ignored and rebuilt, a cache that is not a regular file is never opened,
and writes are atomic (a concurrent writer's entries may be lost, never
mixed). An entry is stored
only for a file whose modification time is at least :data:`RACY_S` older
than the hashing, so a file changed twice within one timestamp tick is
never cached with its first content.

A ROS2 bag is a folder: its identity is the sha256 of the sorted list of its
files' relative paths and checksums.
"""

from __future__ import annotations

import hashlib
import json
import os
import stat
import time
from pathlib import Path

from albot1.atomic import atomic_write
from albot1.data.errors import DataError
from albot1.data.filekind import check_input
from albot1.filetypes import special_kind
from albot1.settings import checksum_cache_file

_BLOCK = 1 << 20
#: Files modified less than this many seconds before they were hashed are not cached (their mtime may not
#: change on a second edit within the file system's timestamp resolution).
RACY_S = 2.0
_FORMAT = 3
#: A cache file larger than this is not read (it holds a few hundred bytes per data file).
_MAX_CACHE_BYTES = 16 * 1024 * 1024
#: Above this many entries, a write drops the entries of files that no longer exist.
_PRUNE_ABOVE = 512
#: Hex digits of a checksum shown to people (tables, report pages); the files keep all 64.
SHORT = 12


def short(sha256: str) -> str:
    """The first :data:`SHORT` hex digits of a checksum, as shown in reports."""
    return sha256[:SHORT]


def hash_stream(path: Path) -> str:
    """Hex sha256 of a regular file's bytes, read in 1 MiB blocks (no cache, no checks)."""
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(_BLOCK), b""):
            digest.update(block)
    return digest.hexdigest()


class _Cache:
    """The checksum cache of this process: the file's entries, re-read when the file changes."""

    def __init__(self) -> None:
        self._entries: dict[str, list[object]] = {}
        self._stamp: tuple[str, int, int] | None = None

    def _load(self, path: Path) -> None:
        try:
            st = path.stat()
        except OSError:
            self._entries, self._stamp = {}, None
            return
        stamp = (str(path), st.st_mtime_ns, st.st_size)
        if stamp == self._stamp:
            return
        self._entries, self._stamp = {}, stamp
        if not stat.S_ISREG(st.st_mode) or st.st_size > _MAX_CACHE_BYTES:
            return  # a FIFO or a device would block or never end; a huge file is no cache of ours
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return  # unreadable or damaged: rebuilt as files are hashed
        if isinstance(data, dict) and data.get("format") == _FORMAT and isinstance(data.get("files"), dict):
            self._entries = {k: v for k, v in data["files"].items() if isinstance(k, str) and _valid_entry(k, v)}

    def get(self, key: str, signature: list[int]) -> str | None:
        self._load(checksum_cache_file())
        entry = self._entries.get(key)
        if entry is not None and entry[:5] == signature:
            return str(entry[5])
        return None

    def put(self, key: str, signature: list[int], sha256: str) -> None:
        path = checksum_cache_file()
        self._load(path)
        self._entries[key] = [*signature, sha256, _seal(key, signature, sha256)]
        if len(self._entries) > _PRUNE_ABOVE:  # files deleted since (temporary copies, old downloads)
            self._entries = {k: v for k, v in self._entries.items() if os.path.exists(k)}
        payload = json.dumps({"format": _FORMAT, "files": self._entries}, sort_keys=True)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            atomic_write(path, lambda tmp: tmp.write_text(payload, encoding="utf-8"))
        except OSError:
            return  # a read-only or full cache folder: the checksum is still right, only not remembered
        self._stamp = None


def _seal(key: str, signature: list[int], sha256: str) -> str:
    """A check over an entry's fields: an entry damaged or edited by hand does not match it and is dropped."""
    return hashlib.sha256(json.dumps([key, signature, sha256]).encode()).hexdigest()[:16]


def _valid_entry(key: str, value: object) -> bool:
    """``[size, mtime_ns, ctime_ns, inode, device, sha256, seal]`` with the types and the seal it must have."""
    if not (
        isinstance(value, list)
        and len(value) == 7
        and all(isinstance(v, int) and not isinstance(v, bool) for v in value[:5])
        and all(isinstance(v, str) for v in value[5:])
    ):
        return False
    return bool(value[6] == _seal(key, value[:5], value[5]))


_CACHE = _Cache()


def _signature(st: os.stat_result) -> list[int]:
    return [st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino, st.st_dev]


def _file_sha256(path: Path, st: os.stat_result) -> str:
    key = str(path.resolve())
    signature = _signature(st)
    cached = _CACHE.get(key, signature)
    if cached is not None:
        return cached
    started = time.time()
    sha = hash_stream(path)
    after = path.stat()
    if _signature(after) != signature:
        raise DataError(f"{path}: the file changed while its checksum was computed; run the command again")
    if started - after.st_mtime_ns / 1e9 >= RACY_S:
        _CACHE.put(key, signature, sha)
    return sha


def content_sha256(path: str | Path, *, folder_ok: bool = True) -> str:
    """sha256 of a regular file, or of a bag folder's files; cached (see the module docstring).

    A FIFO, device, socket or kernel pseudo-file is refused with a DataError
    before anything reads it (:func:`albot1.data.filekind.check_input`).
    """
    p = Path(path)
    st = check_input(p, "a data file or a ROS2 bag folder" if folder_ok else "a data file", folder_ok=folder_ok)
    if not stat.S_ISDIR(st.st_mode):
        return _file_sha256(p, st)
    digest = hashlib.sha256()
    for root, dirs, files in os.walk(p):
        dirs.sort()
        for name in sorted(files):
            member = Path(root) / name
            member_st = member.stat()
            kind = special_kind(member_st.st_mode)
            if kind is not None:
                raise DataError(f"{member}: {kind} inside the bag folder {p}; expected regular files only")
            relative = member.relative_to(p).as_posix()
            digest.update(f"{relative}\0{_file_sha256(member, member_st)}\n".encode())
    return digest.hexdigest()
