"""Why no loader recognises a file: one specific sentence instead of "not a recognised log".

Reached only after every loader's ``sniff`` said no, so it may read the
whole file: an empty file, a file of comments only, a folder, damaged
compressed data (truncated or corrupt ``.gz``/``.bz2``, with the byte offset
and the last complete line), binary data, or the first line that starts no
known format, described by its kind and length (never quoted: the file may hold secrets).
"""

from __future__ import annotations

from pathlib import Path

from albot1.data.errors import DataError, ParseError, UnknownFormatError
from albot1.data.filekind import content_kind
from albot1.data.loaders.compressed import DamagedStream, compression_of, iter_lines, read_head

EXPECTED = (
    "expected a CARMEN log (messages such as FLASER, ROBOTLASER1, ODOM, PARAM; .clf/.log, optionally .gz/.bz2), "
    "an albot log (first line 'ALBOT1-LOG 1'), a ROS1 bag ('#ROSBAG V2.0') or a ROS2 bag folder "
    "(metadata.yaml beside .db3/.mcap files)"
)
#: Why a rawlog is refused as input: the one wording for a rawlog found by its name or content, or named by --from.
RAWLOG_WRITE_ONLY = (
    "albot1 writes rawlogs only as input for MRPT's applications and cannot read them (rawlog is write-only); "
    "give the log it was converted from, or read it with MRPT's own tools"
)
#: Decompressed lines looked at before giving up on finding a first message (the rest is not needed to
#: describe the file, except when it is damaged, which only a full pass can show).
_MAX_LINES = 1_000_000


def _is_binary(line: bytes) -> bool:
    sample = line[:256]
    return b"\0" in sample or sum(b < 9 or 13 < b < 32 for b in sample) > len(sample) // 10


def _is_rawlog(path: Path, head: bytes) -> bool:
    """A ``.rawlog[.gz]`` name, or data that begins like MRPT's serialization (a class-name header, ``mrpt::...``).

    Both, because a user who converted to a rawlog and tries to read it back deserves the true reason
    ("write-only") rather than "binary data of no known format", whatever the file is called.
    """
    if path.name.lower().endswith((".rawlog", ".rawlog.gz")):
        return True
    length = head[0] & 0x7F if head else 0
    return bool(head) and head[0] & 0x80 != 0 and head[1 : 1 + length].startswith(b"mrpt::") and length > 6


def _wide_text(head: bytes) -> str | None:
    """``"UTF-16"``/``"UTF-32"`` when ``head`` starts with that encoding's byte-order mark (a file saved as
    "Unicode" by a Windows editor), else None: named, because "binary data" or a garbled first field would
    hide that the text is fine, only its encoding is not read."""
    if head.startswith((b"\xff\xfe\x00\x00", b"\x00\x00\xfe\xff")):
        return "UTF-32"
    if head.startswith((b"\xff\xfe", b"\xfe\xff")):
        return "UTF-16"
    return None


def unrecognised(path: Path) -> DataError:
    """The error for a path that no loader sniffed as its format."""
    if path.is_dir():
        return UnknownFormatError(f"{path}: a folder without metadata.yaml, not a ROS2 bag; {EXPECTED}")
    if path.stat().st_size == 0:
        return UnknownFormatError(f"{path}: the file is empty (0 bytes); {EXPECTED}")
    compression = compression_of(path)
    packed = "" if compression == "none" else f"{compression}-compressed "
    head = read_head(path)
    if _is_rawlog(path, head):
        return UnknownFormatError(f"{path}: an MRPT rawlog; {RAWLOG_WRITE_ONLY}")
    wide = _wide_text(head)
    if wide:
        return UnknownFormatError(
            f"{path}: {packed}{wide} text (its byte-order mark says so); the logs are read as UTF-8 or ASCII text: "
            f"convert it first (e.g. iconv -f {wide} -t UTF-8); {EXPECTED}"
        )
    if _is_binary(head):
        return UnknownFormatError(f"{path}: binary {packed}data of no known format; {EXPECTED}")
    count = 0
    first: tuple[int, bytes] | None = None
    try:
        for count, line in enumerate(iter_lines(path), start=1):
            stripped = line.strip()
            if first is None and stripped and not stripped.startswith(b"#"):
                first = (count, line)
                if compression == "none":
                    break  # plain data cannot be damaged: the first line says it all
            if count >= _MAX_LINES and first is not None:
                break
    except DamagedStream as damage:
        if count == 0:
            return ParseError(path, damage.describe(" before its first line could be decompressed"))
        return ParseError(path, damage.describe(" after this line (the last complete one)"), line=count)
    except OSError as exc:
        return DataError(f"{path}: cannot be read ({exc.strerror or exc})")
    if first is None:
        if count == 0 and compression == "none":  # not empty (checked above): a UTF-8 byte-order mark alone
            return UnknownFormatError(f"{path}: the file holds no data, only a UTF-8 byte-order mark; {EXPECTED}")
        if count == 0:
            return UnknownFormatError(f"{path}: the {packed}file holds no data (0 bytes decompressed); {EXPECTED}")
        return UnknownFormatError(
            f"{path}: the {packed}file holds only comments and blank lines ({count} lines); {EXPECTED}"
        )
    line_no, line = first
    # The content is described, never quoted: the file may be anything a user pointed at by mistake (/etc/passwd).
    return ParseError(
        path,
        f"the first line that is not a comment ({content_kind(line)}, {len(line.strip())} characters) "
        f"begins no known format; {EXPECTED}",
        line=line_no,
    )
