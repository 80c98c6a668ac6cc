"""CARMEN logs (``.clf``/``.log``, plain, gzip or bzip2) as streamed Sequences.

Poses: ``Frame.odometry`` and ``Frame.reference`` are *robot* poses (the
robot centre), as the odometry fields of FLASER/ROBOTLASER1 lines are; the
laser's pose on the robot is ``metadata.sensor_offset`` (PARAM
``robot_frontlaser_offset``, or the laser-vs-robot pose of the first
ROBOTLASER1 line).

Odometry sources (option ``odometry``):

``"laser-pose"``
    the odometry fields written into every laser line by the CARMEN logger
    (FLASER ``odom_x odom_y odom_theta``, ROBOTLASER1 ``robot_x robot_y
    robot_theta``).
``"odom"``
    SE(2) interpolation of the ODOM lines at the scan's ipc timestamp. ODOM
    stamps may jitter backwards by up to ``time_tolerance`` (the Intel log
    does, by up to 0.9 s); they are sorted, and a scan is only emitted once
    an ODOM stamp later than ``scan time + time_tolerance`` has been read, so
    the result does not depend on chunking. Scans before the first (after
    the last) ODOM line take the first (last) ODOM pose.
``"odom-segments"``
    the GMapping-corrected logs of ``radish-corrected/``: after every FLASER
    the ODOM stream is *re-anchored* at the scan's corrected pose and then
    integrates the raw odometry until the next scan. The odometry of scan k
    is ``odometry[k-1] * between(anchor[k-1], last ODOM before scan k)``,
    starting at the first scan's logged pose; each anchor is checked to
    repeat the preceding scan's pose (see docs/datasets.md for the check on
    all 13 logs).

Reference sources (option ``reference``): ``"none"``; ``"laser-pose"`` (the
FLASER ``x y theta`` / ROBOTLASER1 robot pose fields: the corrected pose in
the SLAM-corrected logs); ``"truepos"`` (TRUEPOS lines interpolated at scan
time); ``"auto"`` (TRUEPOS when the first chunk of the log has TRUEPOS lines,
else none).

ODOM and TRUEPOS lines are only decoded when a pose source uses them.

Streaming: the log is decoded chunk by chunk (2 MiB of text); only scans
waiting for a later ODOM/TRUEPOS line and the ODOM lines that can still
bracket them are buffered. Message types other than the chosen laser, ODOM,
TRUEPOS and PARAM (SYNC, NEFF, NMEA-GGA, a rear laser, ...) are skipped
by design; the names seen at the start of the log are listed in
``metadata.extra["ignored_messages"]``.

Old and new front-laser messages (FLASER, ROBOTLASER1, RAWLASER1) in one
log are refused unless the ``laser`` option names the kind to read: they may
be the same scans written twice (CARMEN's logger writes RAWLASER1 beside
ROBOTLASER1) or two recordings run together, and the loader cannot tell
which, so it neither merges them nor drops one kind without a word. The
error names the count and first line of each kind.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import closing
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from albot1.data.attach import COMMON_OPTIONS
from albot1.data.errors import DataError, ParseError
from albot1.data.loaders.carmen import geometry as geom
from albot1.data.loaders.carmen.checks import span_problem, time_problem
from albot1.data.loaders.carmen.interp import PoseBuffer
from albot1.data.loaders.carmen.parse import (
    FRONT_LASERS,
    LASER_MESSAGES,
    OLD_LASERS,
    LaserBlock,
    ParsedChunk,
    parse_chunk,
    probe_chunk,
    split_messages,
)
from albot1.data.loaders.carmen.source import CHUNK_BYTES, iter_line_chunks, read_head
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata
from albot1.data.relations import read_relations
from albot1.geometry import se2

ODOMETRY_SOURCES = ("laser-pose", "odom", "odom-segments")
REFERENCE_SOURCES = ("none", "laser-pose", "truepos", "auto")
#: A file is taken for a CARMEN log if a line of its first 64 KiB starts with one of these messages
#: (or the "# CARMEN" comment the logger writes first).
_SNIFF_NAMES = frozenset(
    (b"FLASER", b"RLASER", b"ROBOTLASER1", b"RAWLASER1", b"RAWLASER2", b"RAWLASER3", b"RAWLASER4")
    + (b"ODOM", b"PARAM", b"TRUEPOS", b"SYNC")
)
_SNIFF_BYTES = 1 << 16
#: The corrected logs print anchors with the same digits as the scan pose; this only absorbs float noise.
_ANCHOR_TOLERANCE = 1e-5


@dataclass(frozen=True)
class CarmenOptions:
    """Validated loader options (see the module docstring)."""

    odometry: str = "laser-pose"
    reference: str = "auto"
    laser: str | None = None
    max_range: float | None = None
    time_tolerance: float = 1.0
    name: str | None = None
    parallel_bz2: bool = True

    @staticmethod
    def parse(path: Path, options: dict[str, Any]) -> CarmenOptions:
        known = set(CarmenOptions.__dataclass_fields__)
        unknown = sorted(set(options) - known)
        if unknown:
            raise DataError(
                f"{path}: unknown CARMEN loader option(s) {', '.join(unknown)}; "
                f"expected some of {', '.join(sorted(known) + list(COMMON_OPTIONS))}"
            )
        for key in ("max_range", "time_tolerance"):
            if options.get(key) is not None:
                try:
                    options[key] = float(options[key])
                except (TypeError, ValueError):
                    raise DataError(f"{path}: {key}={options[key]!r}; expected a number") from None
        opts = CarmenOptions(**options)
        if opts.odometry not in ODOMETRY_SOURCES:
            raise DataError(f"{path}: odometry={opts.odometry!r}; expected one of {', '.join(ODOMETRY_SOURCES)}")
        if opts.reference not in REFERENCE_SOURCES:
            raise DataError(f"{path}: reference={opts.reference!r}; expected one of {', '.join(REFERENCE_SOURCES)}")
        if opts.laser is not None and opts.laser not in LASER_MESSAGES:
            raise DataError(f"{path}: laser={opts.laser!r}; expected one of {', '.join(LASER_MESSAGES)}")
        if opts.max_range is not None and not (math.isfinite(opts.max_range) and opts.max_range > 0):
            raise DataError(f"{path}: max_range={opts.max_range!r}; expected a positive number of metres")
        if not opts.time_tolerance >= 0:  # inf disables the check (logs whose stamps are garbage)
            raise DataError(f"{path}: time_tolerance={opts.time_tolerance!r}; expected seconds >= 0 (or inf)")
        return opts


class CarmenLoader:
    """Reads CARMEN logs; options as in :class:`CarmenOptions`, plus ``relations`` (a relations file
    path) and ``license``/``citation`` (copied into the metadata; the catalog passes the manifest's)."""

    format_name: ClassVar[str] = "carmen"
    suffixes: ClassVar[tuple[str, ...]] = (".clf", ".log", ".clf.gz", ".log.gz", ".clf.bz2", ".log.bz2")

    def sniff(self, path: Path) -> bool:
        if path.is_dir():
            return False
        for line in read_head(path, _SNIFF_BYTES).split(b"\n"):
            words = line.split(None, 1)
            if words and (words[0] in _SNIFF_NAMES or line.lstrip().startswith(b"# CARMEN")):
                return True
        return False

    def load(self, path: Path, **options: Any) -> Sequence:
        path = Path(path)
        relations_path = options.pop("relations", None)
        license_text = str(options.pop("license", ""))
        citation = str(options.pop("citation", ""))
        opts = CarmenOptions.parse(path, options)
        if not path.is_file():
            raise DataError(f"{path}: no such file")
        probe = _probe(path, opts)
        laser = opts.laser or probe.first_laser
        if laser is None:
            others = sorted(name for name in probe.ignored if name in LASER_MESSAGES)
            hint = (
                f"; the log has {', '.join(f'{probe.ignored[n]} {n}' for n in others)} lines: read them with "
                f"the loader option laser={others[0]} (e.g. 'FILE?laser={others[0]}')"
                if others
                else ""
            )
            raise ParseError(
                path,
                f"no front-laser scans in the first 2 MiB of the log; expected FLASER, ROBOTLASER1 or "
                f"RAWLASER1 lines{hint}",
                line=1,
            )
        if opts.laser is None:
            _refuse_mixed(path, laser, probe)
        if opts.odometry == "laser-pose" and laser.startswith("RAWLASER"):
            raise DataError(f"{path}: {laser} lines carry no pose; use odometry='odom' (ODOM lines)")
        if opts.reference == "laser-pose" and laser.startswith("RAWLASER"):
            raise DataError(f"{path}: {laser} lines carry no pose; reference='laser-pose' is impossible")
        reference = opts.reference
        if reference == "auto":
            reference = "truepos" if len(probe.truepos.lines) else "none"
        params = {name: value for _, name, value in probe.params}
        offset = geom.sensor_offset(params, rear=laser in ("RLASER", "RAWLASER2"))
        if laser == "ROBOTLASER1" and probe.lasers:
            first = probe.lasers[0]
            assert first.robot is not None and first.sensor is not None
            rel = se2.between(first.robot[0], first.sensor[0])
            offset = (float(rel[0]), float(rel[1]), float(rel[2]))
        metadata = SequenceMetadata(
            source=str(path),
            format="carmen",
            license=license_text,
            citation=citation,
            sensor_offset=offset,
            odometry_source=_describe_odometry(opts.odometry, laser),
            reference_source=_describe_reference(reference, laser),
            extra={
                "laser_message": laser,
                "max_range_option": opts.max_range,
                "no_return_rule": f"r >= max_range - {geom.NO_RETURN_MARGIN} m or r == 0",
                "time_tolerance_s": opts.time_tolerance,
                "ignored_messages": sorted(probe.ignored),
            },
        )
        relations = read_relations(relations_path) if relations_path is not None else None
        name = opts.name or _stem(path)
        stream = _Stream(path, opts, laser, reference)
        return Sequence(name, stream.frames, metadata, relations)


def _stem(path: Path) -> str:
    name = path.name
    for suffix in (".gz", ".bz2", ".clf", ".log"):
        if name.endswith(suffix):
            name = name[: -len(suffix)]
    return name or path.name


def _describe_odometry(mode: str, laser: str) -> str:
    if mode == "laser-pose":
        fields = "odom_x odom_y odom_theta" if laser in OLD_LASERS else "robot_x robot_y robot_theta"
        return f"{laser} {fields} fields"
    if mode == "odom":
        return "ODOM lines, SE(2)-interpolated at the scan ipc timestamp"
    return "ODOM increments between scans, re-anchored at each corrected scan pose (GMapping log)"


def _describe_reference(mode: str, laser: str) -> str:
    if mode == "none":
        return ""
    if mode == "truepos":
        return "TRUEPOS lines, SE(2)-interpolated at the scan ipc timestamp"
    fields = "x y theta" if laser in OLD_LASERS else "robot_x robot_y robot_theta"
    return f"{laser} {fields} fields"


_PROBE_BYTES = 1 << 18
_PROBE_LIMIT = CHUNK_BYTES


def _probe(path: Path, opts: CarmenOptions) -> ParsedChunk:
    """Read the head of the log until the first scan (at most 2 MiB): laser type, PARAM values,
    TRUEPOS presence, skipped message names. Small reads keep this cheap on compressed logs."""
    merged = ParsedChunk()
    seen = lines = 0
    with closing(iter_line_chunks(path, chunk_bytes=_PROBE_BYTES, parallel_bz2=False)) as chunks:
        for chunk in chunks:
            part = probe_chunk(path, chunk.first_line, chunk.lines, opts.laser)
            merged.params.extend(part.params)
            merged.ignored.update(part.ignored)
            for name, line in part.ignored_first.items():
                merged.ignored_first.setdefault(name, line)
            merged.message_lines += part.message_lines
            lines = chunk.first_line + len(chunk.lines) - 1
            if not len(merged.truepos.lines):
                merged.truepos = part.truepos
            seen += sum(len(line) + 1 for line in chunk.lines)
            if part.first_laser is not None or seen >= _PROBE_LIMIT:
                merged.first_laser, merged.lasers = part.first_laser, part.lasers
                return merged
    if seen == 0:
        raise ParseError(path, "the file is empty; expected a CARMEN log (one message per line)")
    if merged.message_lines == 0:
        raise ParseError(
            path, f"the log holds only comments and blank lines ({lines} lines); expected CARMEN messages", line=lines
        )
    return merged


def _refuse_mixed(path: Path, laser: str, parsed: ParsedChunk) -> None:
    """A ParseError if ``parsed`` holds front-laser messages of another kind than ``laser``."""
    other = next((name for name in FRONT_LASERS if name != laser and parsed.ignored.get(name)), None)
    if other is None:
        return
    counts, first = _count_messages(path, FRONT_LASERS)
    kinds = [name for name in FRONT_LASERS if counts.get(name)]
    listed = " and ".join(f"{counts[name]} {name} lines (first at line {first[name]})" for name in kinds)
    choices = " or ".join(f"laser={name}" for name in kinds)
    raise ParseError(
        path,
        f"the log mixes front-laser message kinds: {listed}; expected one kind (they may be the same scans "
        f"written twice or two recordings, so none is merged or dropped silently); choose with the loader "
        f"option {choices} (e.g. 'FILE?laser={kinds[0]}'), the other kind is then skipped",
        line=parsed.ignored_first.get(other, first.get(other)),
    )


def _count_messages(path: Path, names: tuple[str, ...]) -> tuple[dict[str, int], dict[str, int]]:
    """Count and first line of each message in ``names`` over the whole log (only on the error path)."""
    counts: dict[str, int] = {}
    first: dict[str, int] = {}
    try:
        for chunk in iter_line_chunks(path):
            for name, rows in split_messages(path, chunk.first_line, chunk.lines).items():
                if name in names:
                    counts[name] = counts.get(name, 0) + len(rows)
                    first.setdefault(name, rows[0][0])
    except ParseError:
        pass  # a damaged tail: the counts so far still describe the mix
    return counts, first


@dataclass(slots=True)
class _Pending:
    """A decoded scan waiting for its poses (ODOM/TRUEPOS look-ahead)."""

    line: int
    timestamp: float
    scan: Scan
    sensor: np.ndarray | None
    robot: np.ndarray | None


class _Stream:
    """Turns parsed chunks into frames; one instance serves every iteration (it holds no state)."""

    def __init__(self, path: Path, opts: CarmenOptions, laser: str, reference: str) -> None:
        self.path = path
        self.opts = opts
        self.laser = laser
        self.reference = reference

    def frames(self) -> Iterator[Frame]:
        return _FrameIterator(self).run()


class _FrameIterator:
    """State of one pass over the log."""

    def __init__(self, stream: _Stream) -> None:
        self.s = stream
        self.path = stream.path
        self.opts = stream.opts
        self.params: dict[str, str] = {}
        self.geometry: dict[int, geom.BeamGeometry] = {}  # by beam count, valid until the next PARAM
        self.pending: list[_Pending] = []
        self.index = 0
        self.last_stamp: tuple[float, int] | None = None
        tol = stream.opts.time_tolerance
        self.odom = PoseBuffer(self.path, "ODOM", tol) if stream.opts.odometry == "odom" else None
        self.truth = PoseBuffer(self.path, "TRUEPOS", tol) if stream.reference == "truepos" else None
        self.skip = frozenset(
            name
            for name, used in (("ODOM", stream.opts.odometry != "laser-pose"), ("TRUEPOS", self.truth is not None))
            if not used
        )
        # odom-segments state
        self.seg_lines = np.zeros(0, dtype=np.int64)
        self.seg_poses = np.zeros((0, 3))
        self.prev_scan: tuple[int, np.ndarray, np.ndarray] | None = None  # line, logged pose, odometry
        self.last_line = 0

    def run(self) -> Iterator[Frame]:
        for chunk in iter_line_chunks(self.path, parallel_bz2=self.opts.parallel_bz2):
            self.last_line = chunk.first_line + len(chunk.lines) - 1
            parsed = parse_chunk(self.path, chunk.first_line, chunk.lines, self.s.laser, self.skip)
            yield from self._consume(parsed)
        yield from self._emit(final=True)
        if self.index == 0:
            raise ParseError(
                self.path, f"no {self.s.laser} scans in the log; expected at least one", line=max(self.last_line, 1)
            )

    def _old_geometry(
        self, block: LaserBlock, params: list[tuple[int, str, str]]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per-row start, step, max range of a FLASER/RLASER block, with the PARAMs logged before each row.

        ``params`` are this chunk's PARAM lines (sorted); ``self.params`` holds those of earlier chunks.
        """
        n = block.beams
        rear = self.s.laser == "RLASER"
        start, step, max_range = (np.empty(len(block.lines)) for _ in range(3))
        state, applied = self.params, 0
        local: dict[int, geom.BeamGeometry] = {}
        for i, line in enumerate(block.lines.tolist()):
            while applied < len(params) and params[applied][0] < line:
                state = dict(state) if state is self.params else state
                state[params[applied][1]] = params[applied][2]
                local.clear()
                applied += 1
            cache = self.geometry if applied == 0 else local
            g = cache.get(n)
            if g is None:
                g = cache[n] = geom.param_geometry(n, state, rear=rear)
                problem = span_problem(n, g.step)
                if problem is not None:
                    raise ParseError(
                        self.path, f"{self.s.laser}: {problem}; the spacing comes from the {g.source}", line=line
                    )
            start[i], step[i], max_range[i] = g.start, g.step, g.max_range
        return start, step, max_range

    def _consume(self, parsed: ParsedChunk) -> Iterator[Frame]:
        if self.opts.laser is None:
            _refuse_mixed(self.path, self.s.laser, parsed)
        params = sorted(parsed.params)
        rows: list[tuple[int, int, int]] = []  # (line, block, row) in file order
        decoded = []
        for b, block in enumerate(parsed.lasers):
            if block.start is None or block.step is None or block.max_range is None:
                start, step, max_range = self._old_geometry(block, params)
            else:
                start, step = block.start, block.step
                max_range = np.where(block.max_range > 0, block.max_range, geom.DEFAULT_MAX_RANGE)
            if self.opts.max_range is not None:
                max_range = np.full(len(block.lines), self.opts.max_range)
            if np.all(start == start[0]) and np.all(step == step[0]):
                shared = geom.beam_angles(block.beams, float(start[0]), float(step[0]))
                angles = [shared] * len(block.lines)
            else:
                angles = [geom.beam_angles(block.beams, a, d) for a, d in zip(start.tolist(), step.tolist())]
            decoded.append(
                (block, geom.clean_block(block.ranges, max_range), angles, block.stamps.tolist(), max_range.tolist())
            )
            rows.extend(zip(block.lines.tolist(), [b] * len(block.lines), range(len(block.lines))))
        for _, name, value in params:
            self.params[name] = value
        if params:
            self.geometry.clear()
        if len(decoded) > 1:
            rows.sort()
        pending = self.pending
        for line, b, i in rows:
            block, ranges, angles, stamps, max_ranges = decoded[b]
            stamp = stamps[i]
            self._check_time(line, stamp)
            pending.append(
                _Pending(
                    line,
                    stamp,
                    Scan(ranges[i], angles[i], stamp, max_ranges[i]),
                    None if block.sensor is None else block.sensor[i],
                    None if block.robot is None else block.robot[i],
                )
            )
        if self.odom is not None:
            self.odom.feed(parsed.odom)
        if self.truth is not None:
            self.truth.feed(parsed.truepos)
        if self.opts.odometry == "odom-segments":
            self.seg_lines = np.concatenate([self.seg_lines, parsed.odom.lines])
            self.seg_poses = np.concatenate([self.seg_poses, parsed.odom.poses])
        yield from self._emit(final=False)

    def _check_time(self, line: int, stamp: float) -> None:
        last = self.last_stamp
        if last is not None:
            prev, prev_line = last
            problem = time_problem(prev, stamp, self.opts.time_tolerance, f" from line {prev_line}")
            if problem is not None:
                raise ParseError(self.path, f"{self.s.laser} {problem}", line=line)
            if stamp <= prev:
                return
        self.last_stamp = (stamp, line)

    def _ready(self, stamp: float) -> bool:
        return all(buf is None or buf.ready(stamp) for buf in (self.odom, self.truth))

    def _emit(self, final: bool) -> Iterator[Frame]:
        done = 0
        wait = not final and (self.odom is not None or self.truth is not None)
        for item in self.pending:
            if wait and not self._ready(item.timestamp):
                break
            yield Frame(self.index, item.scan, self._odometry(item), self._reference(item))
            self.index += 1
            done += 1
        del self.pending[:done]
        oldest = self.pending[0].timestamp if self.pending else (self.last_stamp or (math.inf, 0))[0]
        for buf in (self.odom, self.truth):
            if buf is not None:
                buf.trim(oldest)

    def _odometry(self, rec: _Pending) -> np.ndarray:
        mode = self.opts.odometry
        if mode == "laser-pose":
            assert rec.robot is not None  # RAWLASER + laser-pose is rejected in load()
            return rec.robot.copy()
        if mode == "odom":
            assert self.odom is not None
            return self.odom.at(rec.timestamp, rec.line)
        return self._segment_odometry(rec)

    def _reference(self, rec: _Pending) -> np.ndarray | None:
        if self.s.reference == "none":
            return None
        if self.s.reference == "truepos":
            assert self.truth is not None
            return self.truth.at(rec.timestamp, rec.line)
        pose = rec.sensor if self.s.laser in OLD_LASERS else rec.robot
        assert pose is not None
        return pose.copy()

    def _segment_odometry(self, rec: _Pending) -> np.ndarray:
        logged = rec.sensor if self.s.laser in OLD_LASERS else rec.robot
        if logged is None:
            raise DataError(f"{self.path}: odometry='odom-segments' needs scan lines with poses")
        if self.prev_scan is None:
            odometry = np.array(logged, dtype=np.float64)
        else:
            prev_line, prev_pose, prev_odom = self.prev_scan
            between = (self.seg_lines > prev_line) & (self.seg_lines < rec.line)
            if not between.any():
                raise ParseError(
                    self.path,
                    f"no ODOM line between the scans at lines {prev_line} and {rec.line}; "
                    f"odometry='odom-segments' expects the ODOM lines a GMapping-corrected "
                    f"log writes after every scan",
                    line=rec.line,
                )
            idx = np.flatnonzero(between)
            anchor, end = self.seg_poses[idx[0]], self.seg_poses[idx[-1]]
            gap = np.abs(np.r_[anchor[:2] - prev_pose[:2], se2.wrap(anchor[2] - prev_pose[2])]).max()
            if gap > _ANCHOR_TOLERANCE:
                raise ParseError(
                    self.path,
                    f"the first ODOM after the scan at line {prev_line} is "
                    f"{np.round(anchor, 6).tolist()}, expected it to repeat that scan's pose "
                    f"{np.round(prev_pose, 6).tolist()} (odometry='odom-segments' is only for "
                    f"GMapping-corrected logs; use odometry='odom' or 'laser-pose')",
                    line=int(self.seg_lines[idx[0]]),
                )
            odometry = se2.compose(prev_odom, se2.between(anchor, end))
        keep = self.seg_lines > rec.line
        self.seg_lines, self.seg_poses = self.seg_lines[keep], self.seg_poses[keep]
        self.prev_scan = (rec.line, np.array(logged, dtype=np.float64), odometry)
        return odometry
