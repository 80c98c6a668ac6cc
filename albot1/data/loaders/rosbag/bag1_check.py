"""What is wrong with a ROS1 bag that ``rosbags`` cannot open, in words.

``rosbags`` reads ROS1 bag format 2.0 only and reports a malformed file with
whatever failed inside it (a bare ``AssertionError`` in its index reader for
one of the real bags in ``bad-inputs/``), which tells a user nothing. This
module, reached only after ``rosbags`` has failed, names the format version
of an older bag, or walks the records of a 2.0 bag and reports the first one
that is inconsistent (where it is, what it declares, what was expected).

Bag format 2.0 (the ROS wiki's "Bags/Format/2.0"): after the line
``#ROSBAG V2.0``, records of ``header_len, header, data_len, data``; the
header is ``field_len, name=value`` fields and always has ``op`` (1 byte):
2 message data, 3 bag header, 4 index data, 5 chunk, 6 chunk info,
7 connection. An index-data record (version 1) holds 12 bytes per entry.
"""

from __future__ import annotations

import struct
from pathlib import Path

ROS1_MAGIC = b"#ROSBAG V2.0"
SUPPORTED = "ROS1 bag format 2.0 ('#ROSBAG V2.0', written by every ROS1 release since C Turtle, 2010)"
#: Older headers -> what they are. ROS1's own rosbag tools still read these and write 2.0.
OLD_FORMATS = {
    b"#ROSRECORD V1.2": "ROS1 bag format 1.2 (ROS 0.5 to 1.0, before 2010)",
    b"#ROSRECORD V1.1": "ROS1 bag format 1.1 (early ROS, before 2010)",
    b"#ROSLOG V1.1": "ROS1 bag format 1.1 (early ROS, before 2010)",
    b"#ROSLOG V1.0": "ROS1 bag format 1.0 (early ROS, before 2010)",
}
_OPS = {
    1: "message definition",
    2: "message data",
    3: "bag header",
    4: "index data",
    5: "chunk",
    6: "chunk info",
    7: "connection",
}
_INDEX_ENTRY_BYTES = 12


def version_problem(head: bytes) -> str | None:
    """Why the first line ``head`` is not a bag rosbags can read (None for ``#ROSBAG V2.0``)."""
    if head == ROS1_MAGIC:
        return None
    found = OLD_FORMATS.get(head)
    if found is None and head.startswith((b"#ROSBAG", b"#ROSRECORD", b"#ROSLOG")):
        found = f"an unknown ROS1 bag version {head[:32].decode('ascii', 'replace')!r}"
    if found is None:
        return f"the first line is {head[:32]!r}, not a ROS1 bag header; expected {SUPPORTED}"
    return (
        f"{found}; expected {SUPPORTED}, the only ROS1 format rosbags reads; ROS1's own rosbag tools read the "
        f"old format and write 2.0 (e.g. `rosbag fix OLD.bag NEW.bag`)"
    )


def _fields(header: bytes) -> dict[str, bytes] | None:
    """The ``name=value`` fields of a record header, or None if their lengths do not add up."""
    out: dict[str, bytes] = {}
    i = 0
    while i < len(header):
        if i + 4 > len(header):
            return None
        (size,) = struct.unpack_from("<I", header, i)
        field = header[i + 4 : i + 4 + size]
        if size == 0 or len(field) != size or b"=" not in field:
            return None
        name, _, value = field.partition(b"=")
        out[name.decode("ascii", "replace")] = value
        i += 4 + size
    return out


def damage(path: Path) -> str | None:
    """The first structural inconsistency of a ``#ROSBAG V2.0`` file, in words; None if none is found."""
    data = path.read_bytes()
    size = len(data)
    pos = len(ROS1_MAGIC) + 1
    index_pos: int | None = None
    while pos < size:
        if pos + 4 > size:
            return f"the file ends at byte {size} inside the record header length at byte {pos} (truncated)"
        (header_len,) = struct.unpack_from("<I", data, pos)
        if pos + 8 + header_len > size:
            return (
                f"the record at byte {pos} declares a {header_len}-byte header, but the file ends at byte {size} "
                f"(truncated, or not a record boundary)"
            )
        fields = _fields(data[pos + 4 : pos + 4 + header_len])
        op = fields.get("op", b"") if fields is not None else b""
        if fields is None or len(op) != 1 or op[0] not in _OPS:
            return (
                f"the record at byte {pos} has no readable header (its {header_len}-byte header is not "
                f"name=value fields with an op)"
            )
        kind = _OPS[op[0]]
        (data_len,) = struct.unpack_from("<I", data, pos + 4 + header_len)
        end = pos + 8 + header_len + data_len
        if end > size:
            return (
                f"the {kind} record at byte {pos} declares {data_len} data bytes, but the file ends at byte {size} "
                f"(truncated: an interrupted recording or copy?)"
            )
        if op[0] == 3 and "index_pos" in fields and len(fields["index_pos"]) == 8:
            (index_pos,) = struct.unpack("<Q", fields["index_pos"])
            if index_pos == 0 or index_pos > size:
                return (
                    f"the bag header points its index to byte {index_pos}, but the file has {size} bytes "
                    f"(an unindexed bag from an interrupted recording; ROS1's `rosbag reindex` rebuilds the index)"
                )
        if op[0] == 4 and len(fields.get("count", b"")) == 4 and fields.get("ver") == b"\x01\x00\x00\x00":
            (count,) = struct.unpack("<I", fields["count"])
            if data_len != count * _INDEX_ENTRY_BYTES:
                return (
                    f"the index data record at byte {pos} declares {data_len} data bytes for {count} entries, "
                    f"expected {count * _INDEX_ENTRY_BYTES} ({_INDEX_ENTRY_BYTES} bytes per entry)"
                )
        pos = end
    if index_pos is not None and pos != size:
        return f"the records do not end at the end of the file (byte {pos} of {size})"
    return None


def describe_failure(path: Path, reason: str) -> str:
    """The message for a bag that rosbags failed to open with ``reason``: what is wrong and what is supported."""
    with path.open("rb") as fh:
        head = fh.readline(64).rstrip(b"\n")
    problem = version_problem(head)
    if problem is not None:
        return problem
    found = damage(path)
    if found is None:
        return f"rosbags cannot open this bag ({reason}); expected a readable {SUPPORTED}"
    return (
        f"damaged ROS1 bag: {found} (rosbags stops with: {reason}); expected a consistent {SUPPORTED} "
        f"(a faulty early rosbag writer can also cause this; ROS1's `rosbag reindex` may repair a damaged index)"
    )
