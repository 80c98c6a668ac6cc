"""Format names -> loader/writer classes, imported lazily, and sniffing.

Entries are ``"module:Class"`` strings so that, e.g., ``rosbags`` is imported
only when a bag is actually opened.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from albot1.config.targets import TargetError, resolve_class
from albot1.data import decoded
from albot1.data.errors import DataError, UnknownFormatError
from albot1.data.filekind import check_input
from albot1.data.loaders.base import SequenceLoader, SequenceWriter
from albot1.data.loaders.diagnose import RAWLOG_WRITE_ONLY, unrecognised
from albot1.data.model import Sequence

#: format name -> (loader "module:Class", writer "module:Class" or None)
FORMATS: dict[str, tuple[str, str | None]] = {
    "carmen": ("albot1.data.loaders.carmen.loader:CarmenLoader", "albot1.data.loaders.carmen.writer:CarmenWriter"),
    "ros1": ("albot1.data.loaders.rosbag.loader:Ros1BagLoader", "albot1.data.loaders.rosbag.writer:Ros1BagWriter"),
    "ros2-sqlite3": (
        "albot1.data.loaders.rosbag.loader:Ros2BagLoader",
        "albot1.data.loaders.rosbag.writer:Ros2Sqlite3Writer",
    ),
    "ros2-mcap": (
        "albot1.data.loaders.rosbag.loader:Ros2BagLoader",
        "albot1.data.loaders.rosbag.writer:Ros2McapWriter",
    ),
    "albot-log": (
        "albot1.data.loaders.albot_log.loader:AlbotLogLoader",
        "albot1.data.loaders.albot_log.loader:AlbotLogWriter",
    ),
}

#: formats that can be written but not read: format name -> writer "module:Class".
#: An MRPT rawlog is only ever an input of MRPT's applications (albot1.methods.baselines.mrpt).
WRITE_ONLY_FORMATS: dict[str, str] = {
    "rawlog": "albot1.data.loaders.rawlog.writer:RawlogWriter",
}


def _import(target: str) -> Any:
    try:
        return resolve_class(target)
    except TargetError as exc:
        raise UnknownFormatError(f"a format's loader or writer cannot be loaded: {exc}") from exc


def _check_format(name: str) -> tuple[str, str | None]:
    if name in WRITE_ONLY_FORMATS:
        why = f"; {RAWLOG_WRITE_ONLY}" if name == "rawlog" else ""
        raise UnknownFormatError(f"format {name!r} can be written but not read{why}")
    try:
        return FORMATS[name]
    except KeyError:
        known = [*FORMATS, *WRITE_ONLY_FORMATS]
        raise UnknownFormatError(f"unknown format {name!r}; expected one of: {', '.join(known)}") from None


def loader_for(path: str | Path, format_name: str | None = None) -> SequenceLoader:
    """The loader for ``format_name``, or the first whose ``sniff`` accepts the file."""
    p = Path(path)
    try:
        found = p.exists()
    except (OSError, ValueError) as exc:  # a name too long for the file system, an embedded NUL
        raise DataError(f"{str(p)[:80]}...: not a usable path ({exc.__class__.__name__})") from None
    if found:  # a FIFO, a device, /proc/self/environ: refused by its stat, before a sniff could hang on it
        check_input(p, "a log file or a ROS2 bag folder", folder_ok=True)
    if format_name is not None:
        chosen: SequenceLoader = _import(_check_format(format_name)[0])()
        return chosen
    if not found:
        raise DataError(f"{p}: no such file or directory")
    seen: set[str] = set()
    for loader_target, _ in FORMATS.values():
        if loader_target in seen:
            continue
        seen.add(loader_target)
        loader: SequenceLoader = _import(loader_target)()
        if loader.sniff(p):
            return loader
    raise unrecognised(p)


def writer_for(format_name: str) -> SequenceWriter:
    """The writer of a format name (see :data:`FORMATS` and :data:`WRITE_ONLY_FORMATS`)."""
    if format_name in WRITE_ONLY_FORMATS:
        write_only: SequenceWriter = _import(WRITE_ONLY_FORMATS[format_name])()
        return write_only
    writer_target = _check_format(format_name)[1]
    if writer_target is None:
        raise UnknownFormatError(f"format {format_name!r} can be read but not written")
    writer: SequenceWriter = _import(writer_target)()
    return writer


def load(path: str | Path, format_name: str | None = None, **options: Any) -> Sequence:
    """Open a file of any known format as a Sequence (its frames through the decoded-log cache)."""
    loader = loader_for(path, format_name)
    sequence = loader.load(Path(path), **options)
    return decoded.cached(sequence, Path(path), loader.format_name, type(loader).__module__, options)
