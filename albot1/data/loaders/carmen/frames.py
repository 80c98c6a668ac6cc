"""CARMEN log chunks to frames: beam geometry, scans in file order, time checks, streaming emission.

Each chunk of the log (:mod:`.source`) is parsed (:mod:`.parse`); the laser
rows become scans with their beam angles (from the message, or for the old
FLASER/RLASER messages from the PARAM lines logged before each row), are
checked for time order, and wait in file order until their poses are known
(:class:`~albot1.data.loaders.carmen.poses.PoseSources`). Only those waiting
scans and the pose lines that can still bracket them are kept in memory.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from albot1.data.errors import ParseError
from albot1.data.loaders.beams import seam_repeat
from albot1.data.loaders.carmen import geometry as geom
from albot1.data.loaders.carmen.checks import span_problem, time_problem
from albot1.data.loaders.carmen.options import CarmenOptions
from albot1.data.loaders.carmen.parse import REAR_LASERS, LaserBlock, ParsedChunk, parse_chunk
from albot1.data.loaders.carmen.poses import PendingScan, PoseSources, mount_problem
from albot1.data.loaders.carmen.probe import refuse_mixed
from albot1.data.loaders.carmen.source import iter_line_chunks
from albot1.data.model import Frame, Scan


class FrameStream:
    """Turns parsed chunks into frames; one instance serves every iteration (it holds no state)."""

    def __init__(
        self,
        path: Path,
        opts: CarmenOptions,
        laser: str,
        reference: str,
        mount: tuple[float, float, float],
        *,
        check_mount: bool = False,
    ) -> None:
        self.path = path
        self.opts = opts
        self.laser = laser
        self.reference = reference
        #: the laser's pose on the robot (``metadata.sensor_offset``)
        self.mount = mount
        #: the mount came from the first ROBOTLASER1 line (no PARAM states it): every line must restate it
        self.check_mount = check_mount

    def frames(self) -> Iterator[Frame]:
        return _FrameIterator(self).run()


class _FrameIterator:
    """State of one pass over the log."""

    def __init__(self, stream: FrameStream) -> None:
        self.s = stream
        self.path = stream.path
        self.opts = stream.opts
        self.params: dict[str, str] = {}
        self.geometry: dict[int, geom.BeamGeometry] = {}  # by beam count, valid until the next PARAM
        self.pending: list[PendingScan] = []
        self.index = 0
        self.last_stamp: tuple[float, int] | None = None
        self.poses = PoseSources(stream.path, stream.opts, stream.laser, stream.reference, stream.mount)
        self.last_line = 0
        #: the line of the log's first scan of the chosen laser, once seen
        self.first_scan_line: int | None = None

    def run(self) -> Iterator[Frame]:
        for chunk in iter_line_chunks(self.path, parallel_bz2=self.opts.parallel_bz2):
            self.last_line = chunk.first_line + len(chunk.lines) - 1
            parsed = parse_chunk(self.path, chunk.first_line, chunk.lines, self.s.laser, self.poses.skip)
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
            refuse_mixed(self.path, self.s.laser, parsed)
        params = sorted(parsed.params)
        rows: list[tuple[int, int, int]] = []  # (line, block, row) in file order
        decoded = []
        for b, block in enumerate(parsed.lasers):
            if self.s.check_mount and block.robot is not None and block.sensor is not None:
                found = mount_problem(block.robot, block.sensor, self.s.mount, self.s.laser)
                if found is not None:
                    raise ParseError(self.path, found[1], line=int(block.lines[found[0]]))
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
            ranges = _without_seam(list(geom.clean_block(block.ranges, max_range)), angles)
            decoded.append((block, ranges, angles, block.stamps.tolist(), max_range.tolist()))
            rows.extend(zip(block.lines.tolist(), [b] * len(block.lines), range(len(block.lines))))
        rear = self.s.laser in REAR_LASERS
        if self.first_scan_line is None and rows:
            self.first_scan_line = min(line for line, _, _ in rows)
        for line, name, value in params:
            # before the first scan a PARAM block may restate a value (the last one counts); after it, the mount
            # the scans were placed with must not change (unless the lines state it: each is checked above)
            if not self.s.check_mount and self.first_scan_line is not None and line > self.first_scan_line:
                problem = geom.mount_change_problem(self.params, name, value, self.s.mount, rear=rear)
                if problem is not None:
                    raise ParseError(self.path, problem, line=line)
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
                PendingScan(
                    line,
                    stamp,
                    Scan(ranges[i], angles[i], stamp, max_ranges[i]),
                    None if block.sensor is None else block.sensor[i],
                    None if block.robot is None else block.robot[i],
                )
            )
        self.poses.feed(parsed)
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

    def _emit(self, final: bool) -> Iterator[Frame]:
        done = 0
        poses = self.poses
        wait = not final and poses.look_ahead
        for item in self.pending:
            if wait and not poses.ready(item.timestamp):
                break
            yield Frame(self.index, item.scan, poses.odometry(item), poses.reference(item))
            self.index += 1
            done += 1
        del self.pending[:done]
        oldest = self.pending[0].timestamp if self.pending else (self.last_stamp or (math.inf, 0))[0]
        poses.trim(oldest)


def _without_seam(ranges: list[np.ndarray], angles: list[np.ndarray]) -> list[np.ndarray]:
    """Rows of a block without the repeated last beam of 360-degree scans (``angles`` is edited in place).

    A line with a 360-degree field of view over ``n - 1`` steps measures its
    first direction twice (:func:`seam_repeat`); the last beam is dropped (the
    loader says so when it opens the log: :func:`.geometry.first_line_notes`).
    Rows that share one angle array keep sharing one (read-only) view.
    """
    trimmed: dict[int, np.ndarray | None] = {}
    for i, a in enumerate(angles):
        if id(a) not in trimmed:
            trimmed[id(a)] = a[:-1] if seam_repeat(a) else None
        cut = trimmed[id(a)]
        if cut is not None:
            angles[i], ranges[i] = cut, ranges[i][:-1]
    return ranges
