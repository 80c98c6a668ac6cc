"""Lines of the albot log (format version 1): parsing and formatting, no file I/O.

The specification is in ``docs/formats.md``; :mod:`.loader` opens files
and streams their lines through :class:`ViewParser`. Keeping the line
grammar apart lets the property tests and the writer share it exactly: the
writer checks each SENSOR and VIEW with the reader's own rules
(:func:`sensor_problem`, :func:`view_problem`), so it never writes a log the
reader refuses.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from albot1.data.errors import ParseError, UnwritableError
from albot1.data.loaders.beams import even_spacing
from albot1.data.model import Frame, Scan, mount_problem
from albot1.data.tokens import parse_floats
from albot1.geometry.types import FloatArray

MAGIC = "ALBOT1-LOG"
VERSION = 1
UNITS = "length=m angle=rad time=s"
FRAME = "thesis"
#: A point may sit at most this far (metres) off its beam's ray; more means
#: the file mixes up frames or beam order, not rounding.
POINT_TOLERANCE_M = 1e-3
#: More beams than this is not a planar laser but a corrupt count (and would
#: make the reader allocate the count before seeing a single point).
MAX_BEAMS = 100_000
#: Evenly spaced beams within this (radians) are written as one SENSOR line.
_SPACING_EXACT = 1e-12


class _Sensor:
    """The active beam geometry; ``dirs`` are the unit beam directions in file (left-to-right) order."""

    def __init__(self, angles: FloatArray, max_range: float) -> None:
        self.angles = angles
        self.max_range = max_range
        rev = angles[::-1]
        self.dirs = np.column_stack([-np.sin(rev), np.cos(rev)])


def _numbers(path: Path, line: int, tokens: list[str], what: str) -> FloatArray:
    return parse_floats(path, line, tokens, f"{what}:")


def sensor_problem(beams: int, max_range: float, angles: FloatArray) -> str | None:
    """Why a beam geometry cannot be written or read as a SENSOR line (None if it can)."""
    if not 1 <= beams <= MAX_BEAMS:
        return f"{beams} beams, expected 1 to {MAX_BEAMS}"
    if not (np.isfinite(max_range) and max_range > 0):
        return f"max range is {max_range!r}, expected a finite, positive max range in metres"
    if not np.all(np.isfinite(angles)):
        return "beam angles must be finite numbers (radians)"
    if beams > 1 and not np.all(np.diff(angles) > 0):
        k = int(np.argmax(~(np.diff(angles) > 0)))
        return (
            f"beam angles must be strictly increasing (counter-clockwise), but beam {k + 2} at "
            f"{float(angles[k + 1])!r} rad does not follow beam {k + 1} at {float(angles[k])!r} rad"
        )
    return None


def view_problem(frame: Frame) -> str | None:
    """Why a frame cannot be written or read as a VIEW line under its scan's SENSOR (None if it can)."""
    poses = [frame.scan.timestamp, *np.asarray(frame.odometry, dtype=np.float64).tolist()]
    if frame.reference is not None:
        poses += np.asarray(frame.reference, dtype=np.float64).tolist()
    if not all(np.isfinite(poses)):
        return f"the timestamp and poses must be finite numbers, got {poses}"
    ranges = frame.scan.ranges
    bad = np.isinf(ranges) | (ranges < 0) | (ranges > frame.scan.max_range)
    if bad.any():
        k = int(np.argmax(bad))
        return (
            f"range {k + 1} is {float(ranges[k])!r}, expected ranges in [0, max_range={frame.scan.max_range}] m "
            f"or NaN (no return)"
        )
    return None


def _is_count(token: str) -> bool:
    """A plain non-negative integer: ASCII digits only (``str.isdigit`` accepts superscripts that
    ``int`` rejects) and short enough for ``int`` (which refuses > 4300 digits)."""
    return token.isascii() and token.isdigit() and len(token) <= 12


class ViewParser:
    """Turns the lines after the header into frames, checking every field."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.sensor: _Sensor | None = None
        self.index = 0
        #: whether view 0 has a reference pose, and its line: every later view must agree (all or none)
        self.first_reference: tuple[bool, int] | None = None

    def error(self, line: int, message: str) -> ParseError:
        return ParseError(self.path, message, line=line)

    def sensor_line(self, line: int, tokens: list[str]) -> None:
        explicit = tokens[0] == "SENSOR-ANGLES"
        if len(tokens) < 3 or not _is_count(tokens[1]) or not 1 <= int(tokens[1]) <= MAX_BEAMS:
            raise self.error(
                line, f"expected '{tokens[0]} <beams> <max_range> ...' with beams an integer from 1 to {MAX_BEAMS}"
            )
        beams = int(tokens[1])
        expected = 3 + (beams if explicit else 2)
        if len(tokens) != expected:
            layout = "<a_1> ... <a_beams>" if explicit else "<angle_min> <angle_increment>"
            raise self.error(
                line, f"expected {expected} fields '{tokens[0]} <beams> <max_range> {layout}', got {len(tokens)}"
            )
        values = _numbers(self.path, line, tokens[2:], tokens[0])
        if explicit:
            angles = values[1:]
        else:
            with np.errstate(invalid="ignore", over="ignore"):
                angles = values[1] + np.arange(beams, dtype=np.float64) * values[2]
        with np.errstate(invalid="ignore", over="ignore"):
            problem = sensor_problem(beams, float(values[0]), angles)
        if problem is not None:
            raise self.error(line, f"{tokens[0]}: {problem}")
        self.sensor = _Sensor(angles, float(values[0]))

    def view_line(self, line: int, tokens: list[str]) -> Frame:
        if self.sensor is None:
            raise self.error(line, "VIEW before any SENSOR line; the beam geometry must come first")
        n = self.sensor.angles.shape[0]
        has_ref = len(tokens) > 6 and tokens[6] != "-"
        head = 9 if has_ref else 7
        if len(tokens) != head + 2 * n:
            raise self.error(
                line,
                f"expected 'VIEW <index> <t> <x> <y> <theta> <- | rx ry rtheta>' and {2 * n} "
                f"point coordinates ({n} beams), got {len(tokens)} fields",
            )
        if not _is_count(tokens[1]) or int(tokens[1]) != self.index:
            raise self.error(line, f"expected view index {self.index}, got {tokens[1]!r}")
        self._check_reference_presence(line, has_ref)
        poses = _numbers(self.path, line, tokens[2:6] + (tokens[6:9] if has_ref else []), "VIEW time/pose")
        if not np.all(np.isfinite(poses)):
            raise self.error(line, "the timestamp and poses must be finite numbers")
        t = float(poses[0])
        ranges = self._ranges(line, _numbers(self.path, line, tokens[head:], "VIEW points").reshape(n, 2))
        frame = Frame(
            self.index,
            Scan(ranges, self.sensor.angles, t, self.sensor.max_range),
            poses[1:4].copy(),
            poses[4:7].copy() if has_ref else None,
        )
        self.index += 1
        return frame

    def _check_reference_presence(self, line: int, has_ref: bool) -> None:
        """Reference poses for every view or for none, as every other source gives them.

        A run scores reference poses only when every scan has one, so a log with
        some ``-`` views used to lose all its reference poses without a word
        ("the dataset has no reference poses").
        """
        if self.first_reference is None:
            self.first_reference = (has_ref, line)
            return
        first_has, first_line = self.first_reference
        if has_ref != first_has:
            which = ("has a reference pose", "has none ('-')")
            raise self.error(
                line,
                f"view {self.index} {which[0] if has_ref else which[1]}, but view 0 (line {first_line}) "
                f"{which[0] if first_has else which[1]}; expected a reference pose for every view or for none "
                f"(scores need one for every scan)",
            )

    def _ranges(self, line: int, points: FloatArray) -> FloatArray:
        assert self.sensor is not None
        nan = np.isnan(points)
        if np.any(nan[:, 0] != nan[:, 1]) or np.any(np.isinf(points)):
            raise self.error(line, "a point must be two finite numbers, or 'nan nan' for a beam without return")
        r = np.hypot(points[:, 0], points[:, 1])
        along = np.einsum("ij,ij->i", points, self.sensor.dirs)
        off = np.abs(points[:, 0] * self.sensor.dirs[:, 1] - points[:, 1] * self.sensor.dirs[:, 0])
        with np.errstate(invalid="ignore"):
            checks = (
                (off > POINT_TOLERANCE_M, "is {off:.4g} m off its beam at {angle!r} rad"),
                (along < -POINT_TOLERANCE_M, "lies behind the robot on its beam at {angle!r} rad"),
                (r > self.sensor.max_range * (1 + 1e-12), "lies {r!r} m away, beyond the max range {max_range!r} m"),
            )
        for bad, template in checks:
            if np.any(bad):
                k = int(np.argmax(bad))
                problem = template.format(
                    off=float(off[k]),
                    angle=float(self.sensor.angles[-1 - k]),
                    r=float(r[k]),
                    max_range=self.sensor.max_range,
                )
                raise self.error(
                    line,
                    f"point {k + 1} ({float(points[k, 0])!r}, {float(points[k, 1])!r}) {problem}; "
                    f"expected thesis-frame points (x = -r sin a, y = r cos a) listed left to right "
                    f"within the max range",
                )
        return r[::-1].copy()


@dataclass(frozen=True)
class Header:
    """What the header lines say: the sequence's NAME (None if absent) and the laser's MOUNT on the robot."""

    name: str | None
    #: ``MOUNT x y theta``: the laser's pose in the robot frame (m, m, rad; the sequence's ``sensor_offset``)
    mount: tuple[float, float, float]


def mount_line(offset: tuple[float, float, float]) -> str:
    """The MOUNT header line of a laser pose in the robot frame (written only when it is not zero)."""
    return "MOUNT " + _fmt(offset)


def _mount(path: Path, line: int, value: str) -> tuple[float, float, float]:
    tokens = value.split()
    if len(tokens) != 3:
        raise ParseError(
            path, f"expected 'MOUNT <x> <y> <theta>' (the laser's pose on the robot), got {value!r}", line=line
        )
    x, y, theta = (float(v) for v in _numbers(path, line, tokens, "MOUNT"))
    if not all(np.isfinite((x, y, theta))):
        raise ParseError(path, f"MOUNT {value}: expected three finite numbers (m, m, rad)", line=line)
    problem = mount_problem((x, y, theta))
    if problem is not None:
        raise ParseError(path, f"MOUNT {value}: {problem}", line=line)
    return x, y, theta


def read_header(path: Path, lines: Iterator[tuple[int, str]]) -> tuple[Header, list[tuple[int, str]]]:
    """Checks magic, version, UNITS and FRAME; returns NAME and MOUNT, and the lines read past the header."""
    first = next(lines, None)
    if first is None:
        raise ParseError(path, f"empty file; expected the first line '{MAGIC} {VERSION}'", line=1)
    tokens = first[1].split()
    if len(tokens) != 2 or tokens[0] != MAGIC:
        raise ParseError(path, f"expected the first line '{MAGIC} {VERSION}', got {first[1].strip()[:60]!r}", line=1)
    if tokens[1] != str(VERSION):
        raise ParseError(
            path, f"unsupported {MAGIC} version {tokens[1]!r}; this reader knows version {VERSION}", line=1
        )
    seen: dict[str, str] = {}
    seen_at: dict[str, int] = {}
    mount = (0.0, 0.0, 0.0)  # absent: the laser sits at the robot's centre, facing forwards
    for lineno, text in lines:
        stripped = text.strip()
        if not stripped or stripped.startswith("#"):
            continue
        key, value = (*stripped.split(None, 1), "")[:2]  # fields split by any whitespace, as in the VIEW lines
        if key in ("SENSOR", "SENSOR-ANGLES", "VIEW"):
            missing = [k for k in ("UNITS", "FRAME") if k not in seen]
            if missing:
                raise ParseError(
                    path,
                    f"the header lacks {' and '.join(missing)} before the first {key} line "
                    f"(expected 'UNITS {UNITS}' and 'FRAME {FRAME}')",
                    line=lineno,
                )
            return Header(seen.get("NAME"), mount), [(lineno, text)]
        if key not in ("UNITS", "FRAME", "NAME", "MOUNT"):
            raise ParseError(
                path, f"unknown header line {key!r}; expected UNITS, FRAME, NAME, MOUNT, SENSOR or VIEW", line=lineno
            )
        value = " ".join(value.split())
        if key == "UNITS" and value != UNITS:
            raise ParseError(path, f"expected 'UNITS {UNITS}' (no other units are defined), got {value!r}", line=lineno)
        if key == "FRAME" and value != FRAME:
            raise ParseError(path, f"expected 'FRAME {FRAME}', got {value!r}", line=lineno)
        if key == "MOUNT":
            mount = _mount(path, lineno, value)  # each MOUNT line checked at its own line
        if key in seen and value != seen[key]:
            # two recordings' headers joined, or an edit that added a line: which one holds cannot be told
            raise ParseError(
                path,
                f"{key} {value!r}, but line {seen_at[key]} says {key} {seen[key]!r}; expected one {key} line "
                f"(or the same value repeated)",
                line=lineno,
            )
        seen_at.setdefault(key, lineno)  # the first line of each: what a repeat is compared with
        seen[key] = value
    raise ParseError(path, "the file has a header but no SENSOR or VIEW line")


def _fmt(values: Any) -> str:
    return " ".join(map(repr, np.asarray(values, dtype=np.float64).tolist()))


def sensor_line(scan: Scan) -> str:
    n = scan.beams
    spacing = even_spacing(scan.angles, _SPACING_EXACT) if n > 1 else None
    if spacing is not None:
        return f"SENSOR {n} {float(scan.max_range)!r} {spacing[0]!r} {spacing[1]!r}"
    return f"SENSOR-ANGLES {n} {float(scan.max_range)!r} {_fmt(scan.angles)}"


def check_frame(frame: Frame) -> None:
    """A DataError naming the frame if the reader would refuse its SENSOR or VIEW line."""
    scan = frame.scan
    problem = sensor_problem(scan.beams, float(scan.max_range), scan.angles)
    where = "SENSOR"
    if problem is None:
        problem, where = view_problem(frame), "VIEW"
    if problem is not None:
        raise UnwritableError(f"scan #{frame.index}: {where} {problem}; the albot-log reader would refuse it")


def view_line(frame: Frame) -> str:
    """One VIEW record (without newline) for a frame."""
    scan = frame.scan
    # REP-103 points of every beam, reversed to the file's left-to-right order, turned into the thesis frame.
    rep = scan.points(keep_missing=True)[::-1]
    points = np.column_stack([-rep[:, 1], rep[:, 0]])
    ref = _fmt(frame.reference) if frame.reference is not None else "-"
    return f"VIEW {frame.index} {float(scan.timestamp)!r} {_fmt(frame.odometry)} {ref} {_fmt(points.ravel())}"
