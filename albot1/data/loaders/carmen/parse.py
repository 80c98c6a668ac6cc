"""CARMEN message lines -> numbers, many lines at a time.

Pure parsing (no file access): a chunk of raw lines becomes column-wise laser blocks,
ODOM/TRUEPOS pose arrays and PARAM values, each tagged with its 1-based line
number. Numbers are converted by numpy's C tokenizer on whole groups of lines
with the same layout (one ``np.loadtxt`` per group), never token by token in
Python; this is what makes the 13631-scan Intel log parse in a fraction of a
second. When a group fails to convert, the lines are re-checked one by one to
name the first offending line and field, so error messages stay precise.

Message layouts (after the name; every message ends with
``ipc_timestamp ipc_hostname logger_timestamp``)::

    FLASER|RLASER  n r1..rn x y theta odom_x odom_y odom_theta
    ROBOTLASER1|2  type start_angle fov resolution max_range accuracy remission_mode
                   n r1..rn m e1..em laser_x laser_y laser_theta robot_x robot_y robot_theta
                   tv rv forward_safety side_safety turn_axis
    RAWLASER1..4   type start_angle fov resolution max_range accuracy remission_mode
                   n r1..rn m e1..em
    ODOM           x y theta tv rv accel
    TRUEPOS        true_x true_y true_theta odom_x odom_y odom_theta
    PARAM          name value

The timestamp used everywhere is ``ipc_timestamp`` (the ground-truth
relations of Kuemmerle et al. are keyed by it). Fields are separated by any
run of spaces or tabs (CARMEN is whitespace-separated); the common
single-space layout takes the fastest path. What a line may hold is in
:mod:`.checks`, shared with the writer.
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.checks import MAX_BEAMS, geometry_problem, ranges_problem
from albot1.data.loaders.carmen.geometry import param_problem
from albot1.data.tokens import is_number
from albot1.geometry.types import FloatArray

OLD_LASERS = ("FLASER", "RLASER")
NEW_LASERS = ("ROBOTLASER1", "ROBOTLASER2", "RAWLASER1", "RAWLASER2", "RAWLASER3", "RAWLASER4")
LASER_MESSAGES = OLD_LASERS + NEW_LASERS
#: The messages that carry the laser's and the robot's pose with every scan (CARMEN's robot module, front and rear).
ROBOT_LASERS = ("ROBOTLASER1", "ROBOTLASER2")
#: The *rear* laser's messages: their mount is the ``robot_rearlaser_*`` PARAMs' (a laser looking backwards).
REAR_LASERS = ("RLASER", "ROBOTLASER2", "RAWLASER2")
#: Laser messages CARMEN's playback defines that this loader does not read (a third to fifth laser, and
#: LASER3..5, the old form of RAWLASER3..5): named when a log holds no laser the loader reads.
UNREAD_LASERS = ("LASER3", "LASER4", "LASER5", "RAWLASER5", "ROBOTLASER3", "ROBOTLASER4", "ROBOTLASER5")
#: The message kinds of the *front* laser, old and new; a log mixing them is refused unless one is chosen.
FRONT_LASERS = ("FLASER", "ROBOTLASER1", "RAWLASER1")
POSE_MESSAGES = ("ODOM", "TRUEPOS")
#: Message names are upper-case words; anything else is not a CARMEN line.
_NAME = re.compile(rb"^[A-Z][A-Z0-9_-]*$")
_TRAILER = "ipc_timestamp ipc_hostname logger_timestamp"
_LAYOUT = {
    "FLASER": "n r1..rn x y theta odom_x odom_y odom_theta " + _TRAILER,
    "RLASER": "n r1..rn x y theta odom_x odom_y odom_theta " + _TRAILER,
    "ROBOTLASER1": (
        "laser_type start_angle fov resolution max_range accuracy remission_mode n r1..rn m e1..em "
        "laser_x laser_y laser_theta robot_x robot_y robot_theta tv rv forward_safety side_safety "
        "turn_axis " + _TRAILER
    ),
    "ROBOTLASER2": (
        "laser_type start_angle fov resolution max_range accuracy remission_mode n r1..rn m e1..em "
        "laser_x laser_y laser_theta robot_x robot_y robot_theta tv rv forward_safety side_safety "
        "turn_axis " + _TRAILER
    ),
    "RAWLASER": "laser_type start_angle fov resolution max_range accuracy remission_mode n r1..rn m e1..em " + _TRAILER,
    "ODOM": "x y theta tv rv accel " + _TRAILER,
    "TRUEPOS": "true_x true_y true_theta odom_x odom_y odom_theta " + _TRAILER,
}


@dataclass(frozen=True, slots=True)
class LaserBlock:
    """Scan messages of one layout (same beam count), column-wise, as logged.

    Ranges are not yet cleaned of max-range readings. ``start``/``step``/
    ``max_range`` (per row, radians and metres) are None for FLASER/RLASER,
    whose geometry comes from PARAM lines or documented defaults.
    ``sensor`` is the logged laser pose, ``robot`` the logged robot
    (odometry) pose; both None for RAWLASER messages, which carry no pose.
    """

    lines: NDArray[np.int64]
    stamps: FloatArray
    ranges: FloatArray
    start: FloatArray | None
    step: FloatArray | None
    max_range: FloatArray | None
    sensor: FloatArray | None
    robot: FloatArray | None

    @property
    def beams(self) -> int:
        return int(self.ranges.shape[1])


@dataclass(frozen=True, slots=True)
class PoseRecords:
    """Pose messages of one kind: 1-based lines, ipc timestamps, poses ``(k, 3)``."""

    lines: NDArray[np.int64]
    timestamps: FloatArray
    poses: FloatArray

    @staticmethod
    def empty() -> PoseRecords:
        return PoseRecords(np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros((0, 3)))


@dataclass
class ParsedChunk:
    """Everything one chunk of lines contributed, each item tagged with its line."""

    lasers: list[LaserBlock] = field(default_factory=list)
    odom: PoseRecords = field(default_factory=PoseRecords.empty)
    truepos: PoseRecords = field(default_factory=PoseRecords.empty)
    params: list[tuple[int, str, str]] = field(default_factory=list)
    ignored: Counter[str] = field(default_factory=Counter)
    #: first line of each ignored message name in this chunk
    ignored_first: dict[str, int] = field(default_factory=dict)
    first_laser: str | None = None
    #: lines holding a message (not blank, not a comment) in this chunk
    message_lines: int = 0
    #: the last line read (set by the probe: how far its counts reach)
    last_line: int = 0


_KNOWN = frozenset(LASER_MESSAGES + POSE_MESSAGES + ("PARAM",))


def _irregular(data: bytes) -> bool:
    """True if ``data`` holds a tab or two spaces in a row.

    numpy instead of ``b"  " in data``: CPython's substring search is slow for
    a needle made of the text's most frequent byte (2 ms per 2 MiB of log,
    against 0.1 ms here), and this runs on every chunk and every group.
    """
    if b"\t" in data:
        return True
    spaces = np.frombuffer(data, dtype=np.uint8) == 32
    return bool((spaces[1:] & spaces[:-1]).any())


def split_messages(path: Path, first_line: int, lines: list[bytes]) -> dict[str, list[tuple[int, bytes]]]:
    """Lines grouped by message name -> ``(line number, rest of line)``; comments and blanks dropped.

    The rest of every line comes back with its fields single-space separated,
    whatever whitespace the file used between them.
    """
    groups: dict[bytes, list[tuple[int, bytes]]] = {}
    known = {name.encode(): name for name in _KNOWN}
    if _irregular(b"\n".join(lines)):
        lines = [b" ".join(raw.split()) if b"\t" in raw or b"  " in raw else raw for raw in lines]
    for offset, raw in enumerate(lines):
        head, _, rest = raw.partition(b" ")
        if head in known:  # fast path: a well-formed known message
            groups.setdefault(head, []).append((first_line + offset, rest.rstrip()))
            continue
        line = raw.strip()
        if not line or line.startswith(b"#"):
            continue
        parts = line.split(None, 1)
        head, rest = parts[0], (parts[1].strip() if len(parts) > 1 else b"")
        if not _NAME.match(head):
            shown = line[:40].decode("utf-8", "replace")
            raise ParseError(
                path,
                f"expected a CARMEN message name (upper-case word such as FLASER, ODOM, "
                f"PARAM) or a '#' comment, found {shown!r}",
                line=first_line + offset,
            )
        groups.setdefault(head, []).append((first_line + offset, rest))
    return {name.decode("ascii"): rows for name, rows in groups.items()}


def _describe(token: bytes) -> str:
    return repr(token[:20].decode("utf-8", "replace"))


def _check_line(path: Path, line: int, name: str, tokens: list[bytes], expected: int, text_at: int) -> None:
    """Raise the precise error for one line whose bulk conversion failed."""
    layout = _LAYOUT["RAWLASER" if name.startswith("RAWLASER") else name]
    if len(tokens) != expected:
        raise ParseError(
            path, f"{name} has {len(tokens)} fields after the name, expected {expected} ({layout})", line=line
        )
    for i, tok in enumerate(tokens):
        if i != text_at % expected and not is_number(tok):
            raise ParseError(path, f"{name} field {i + 1} is {_describe(tok)}, expected a number ({layout})", line=line)


def _bulk(path: Path, name: str, rows: list[tuple[int, bytes]], expected: int) -> FloatArray:
    """Numbers of ``rows`` that all have ``expected`` fields (hostname, second to last, dropped)."""
    host_at = expected - 2
    body = b"\n".join(rest for _, rest in rows)
    # loadtxt ignores surplus columns, so field counts are checked here: one count over the whole
    # group when it is single-spaced, line by line otherwise.
    single_spaced = body.count(b" ") == len(rows) * (expected - 1) and not _irregular(body)
    if not single_spaced:
        for line, rest in rows:
            tokens = rest.split()
            if len(tokens) != expected:
                _check_line(path, line, name, tokens, expected, host_at)
    try:
        # a fixed one-space delimiter is ~10 % faster than whitespace splitting
        values = np.loadtxt(
            _Lines(body),
            dtype=np.float64,
            comments=None,
            ndmin=2,
            delimiter=" " if single_spaced else None,
            usecols=[i for i in range(expected) if i != host_at],
        )
        if values.shape != (len(rows), expected - 1):
            raise ValueError("row count")
        return values
    except ValueError as exc:
        for line, rest in rows:
            _check_line(path, line, name, rest.split(), expected, host_at)
        line, reason = _failing_line(name, rows, expected, host_at, single_spaced, exc)
        raise ParseError(
            path, f"{name} line could not be read as numbers ({reason}); expected {_LAYOUT.get(name, name)}", line=line
        ) from None


def _failing_line(
    name: str, rows: list[tuple[int, bytes]], expected: int, host_at: int, single_spaced: bool, exc: ValueError
) -> tuple[int, str]:
    """The line (and numpy's reason) that fails the bulk conversion when every token passed
    :func:`~albot1.data.tokens.is_number`: each line is converted alone, so the error names the true line."""
    for line, rest in rows:
        try:
            np.loadtxt(
                [rest.decode("latin-1")],
                dtype=np.float64,
                comments=None,
                delimiter=" " if single_spaced else None,
                usecols=[i for i in range(expected) if i != host_at],
            )
        except ValueError as alone:
            return line, str(alone)
    return rows[0][0], str(exc)  # pragma: no cover - the group failed, so one of its lines does


class _Lines:
    """Iterable of text lines over a bytes body (what ``np.loadtxt`` reads fastest)."""

    def __init__(self, body: bytes) -> None:
        self._text = body.decode("latin-1")

    def __iter__(self) -> Iterator[str]:
        return iter(self._text.split("\n"))


def _first_int(path: Path, name: str, line: int, token: bytes | None, what: str, *, beams: bool = True) -> int:
    """A count field: the beam count (1..MAX_BEAMS) or, with ``beams=False``, a remission count (>= 0)."""
    try:
        if token is None:
            raise ValueError
        value = int(token)
    except ValueError:
        shown = "nothing" if token is None else _describe(token)
        raise ParseError(
            path,
            f"{name} {what} is {shown}, expected a non-negative integer "
            f"({_LAYOUT['RAWLASER' if name.startswith('RAWLASER') else name]})",
            line=line,
        ) from None
    low = 1 if beams else 0
    if not low <= value <= MAX_BEAMS:
        raise ParseError(path, f"{name} {what} is {value}, expected {low} to {MAX_BEAMS}", line=line)
    return value


def _check_values(path: Path, name: str, lines: NDArray[np.int64], ranges: FloatArray, finite: FloatArray) -> None:
    """The rules of :func:`.checks.ranges_problem`; poses and timestamps finite."""
    found = ranges_problem(ranges)
    if found is not None:
        raise ParseError(path, f"{name} {found[1]}", line=int(lines[found[0]]))
    bad_rows = ~np.isfinite(finite).all(axis=1)
    if bad_rows.any():
        row = int(np.argmax(bad_rows))
        value = float(finite[row][~np.isfinite(finite[row])][0])
        raise ParseError(
            path, f"{name} pose/timestamp fields contain {value!r}, expected finite numbers", line=int(lines[row])
        )


def _beam_count(path: Path, name: str, line: int, rest: bytes) -> int:
    cut = rest.find(b" ")
    return _first_int(path, name, line, rest[:cut] if cut > 0 else (rest or None), "beam count")


def parse_old_lasers(path: Path, name: str, rows: list[tuple[int, bytes]]) -> list[LaserBlock]:
    """FLASER/RLASER lines -> one block per beam count."""
    by_token: dict[bytes, list[tuple[int, bytes]]] = {}
    for line, rest in rows:  # group by the beam-count *text*; convert each distinct one once
        cut = rest.find(b" ")
        by_token.setdefault(rest[:cut] if cut >= 0 else rest, []).append((line, rest))
    by_n: dict[int, list[tuple[int, bytes]]] = {}
    for group in by_token.values():
        line, rest = group[0]
        by_n.setdefault(_beam_count(path, name, line, rest), []).extend(group)
    out: list[LaserBlock] = []
    for n, group in by_n.items():
        if len(by_token) > 1:
            group.sort()
        v = _bulk(path, name, group, n + 10)
        lines = np.fromiter((ln for ln, _ in group), dtype=np.int64, count=len(group))
        ranges = v[:, 1 : n + 1]
        tail = v[:, n + 1 :]  # x y th ox oy oth ipc_ts logger_ts
        _check_values(path, name, lines, ranges, tail)
        out.append(LaserBlock(lines, tail[:, 6], ranges, None, None, None, tail[:, 0:3], tail[:, 3:6]))
    return out


def parse_new_lasers(path: Path, name: str, rows: list[tuple[int, bytes]]) -> list[LaserBlock]:
    """ROBOTLASER1/2 and RAWLASERn lines -> one block per (beams, remissions) layout."""
    with_pose = name in ROBOT_LASERS
    extra = 11 if with_pose else 0
    by_shape: dict[tuple[int, int], list[tuple[int, bytes]]] = {}
    for line, rest in rows:
        tokens = rest.split()
        n = _first_int(path, name, line, tokens[7] if len(tokens) > 7 else None, "beam count (field 8)")
        m_at = 8 + n
        m = _first_int(
            path,
            name,
            line,
            tokens[m_at] if len(tokens) > m_at else None,
            f"remission count (field {m_at + 1})",
            beams=False,
        )
        by_shape.setdefault((n, m), []).append((line, rest))
    out: list[LaserBlock] = []
    for (n, m), group in by_shape.items():
        v = _bulk(path, name, group, 7 + 1 + n + 1 + m + extra + 3)
        lines = np.fromiter((ln for ln, _ in group), dtype=np.int64, count=len(group))
        ranges = v[:, 8 : 8 + n]
        head = v[:, 0:7]
        pose_at = 9 + n + m
        stamps = v[:, -2]
        poses = v[:, pose_at : pose_at + 6] if with_pose else np.zeros((len(group), 0))
        _check_values(path, name, lines, ranges, np.column_stack([head[:, 1:5], poses, stamps]))
        found = geometry_problem(n, head[:, 1], head[:, 2], head[:, 3], head[:, 4])
        if found is not None:
            raise ParseError(path, f"{name} {found[1]}", line=int(lines[found[0]]))
        out.append(
            LaserBlock(
                lines,
                stamps,
                ranges,
                head[:, 1],
                head[:, 3],
                head[:, 4],
                poses[:, 0:3] if with_pose else None,
                poses[:, 3:6] if with_pose else None,
            )
        )
    return out


def parse_poses(path: Path, name: str, rows: list[tuple[int, bytes]]) -> PoseRecords:
    """ODOM / TRUEPOS lines -> the first three numbers as poses, with their ipc timestamps."""
    if not rows:
        return PoseRecords.empty()
    v = _bulk(path, name, rows, 9)
    lines = np.array([ln for ln, _ in rows], dtype=np.int64)
    _check_values(path, name, lines, np.zeros((len(rows), 0)), v)
    return PoseRecords(lines, v[:, 6].copy(), v[:, 0:3].copy())


def parse_params(path: Path, rows: list[tuple[int, bytes]]) -> list[tuple[int, str, str]]:
    """PARAM ``name value ...`` -> (line, name, value); the value is kept as text."""
    out = []
    for line, rest in rows:
        parts = rest.split()
        if len(parts) < 2:
            raise ParseError(path, "PARAM needs a name and a value (PARAM name value " + _TRAILER + ")", line=line)
        name, value = parts[0].decode("utf-8", "replace"), parts[1].decode("utf-8", "replace")
        problem = param_problem(name, value)
        if problem is not None:
            raise ParseError(path, problem, line=line)
        out.append((line, name, value))
    return out


def _first_front_laser(groups: dict[str, list[tuple[int, bytes]]]) -> str | None:
    """The front-laser message (FLASER, ROBOTLASER1 or RAWLASER1) that appears first in ``groups``."""
    candidates = [(rows[0][0], nm) for nm, rows in groups.items() if nm in ("FLASER", "ROBOTLASER1", "RAWLASER1")]
    return min(candidates)[1] if candidates else None


def probe_chunk(path: Path, first_line: int, lines: list[bytes], laser: str | None) -> ParsedChunk:
    """What ``load()`` needs before streaming, cheaply: the laser message and its first line only,
    PARAM values, TRUEPOS lines and the names of skipped messages (ODOM is left to the stream)."""
    groups = split_messages(path, first_line, lines)
    message_lines = sum(len(rows) for rows in groups.values())
    if laser is None:
        laser = _first_front_laser(groups)
    groups.pop("ODOM", None)
    if laser is not None and laser in groups:
        groups[laser] = groups[laser][:1]
    chunk = _parse_groups(path, groups, laser)
    chunk.message_lines = message_lines
    return chunk


def parse_chunk(
    path: Path, first_line: int, lines: list[bytes], laser: str | None, skip: frozenset[str] = frozenset()
) -> ParsedChunk:
    """Parse a chunk; ``laser`` is the scan message to decode (None: the first front laser seen here).

    Message names in ``skip`` (e.g. ODOM when odometry comes from the laser lines) are not
    decoded at all: their numbers cannot change the result, and ODOM is half the Intel log.
    """
    groups = split_messages(path, first_line, lines)
    for name in skip:
        groups.pop(name, None)
    if laser is None:
        laser = _first_front_laser(groups)
    return _parse_groups(path, groups, laser)


def _parse_groups(path: Path, groups: dict[str, list[tuple[int, bytes]]], laser: str | None) -> ParsedChunk:
    chunk = ParsedChunk()
    chunk.first_laser = laser
    for name, rows in groups.items():
        if name == laser:
            parser = parse_old_lasers if name in OLD_LASERS else parse_new_lasers
            chunk.lasers = sorted(parser(path, name, rows), key=lambda blk: int(blk.lines[0]))
        elif name == "ODOM":
            chunk.odom = parse_poses(path, name, rows)
        elif name == "TRUEPOS":
            chunk.truepos = parse_poses(path, name, rows)
        elif name == "PARAM":
            chunk.params = parse_params(path, rows)
        else:
            chunk.ignored[name] += len(rows)
            chunk.ignored_first[name] = rows[0][0]
    return chunk
