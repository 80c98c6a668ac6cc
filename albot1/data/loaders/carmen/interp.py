"""A bounded look-ahead buffer of timestamped poses (ODOM or TRUEPOS lines).

Scans are streamed, but interpolating a pose at a scan's time needs the
first pose message *after* it, which may be further down the log. The
buffer answers ``ready(t)`` once that is guaranteed and drops poses that no
later scan can need, so memory stays bounded on arbitrarily long logs.

Pose stamps may go backwards by at most ``tolerance`` seconds (the Intel log
has ODOM stamps up to 0.9 s out of order); a larger step back is a
ParseError. ``ready(t)`` waits for a stamp beyond ``t + tolerance``, after
which no later message can land before ``t``: the interpolated pose is the
same as if the whole log had been sorted first. A pose stamped exactly at the
scan's time is taken as is (no interpolation), paired by file order when
several share the stamp: this is what makes logs written by
:class:`~albot1.data.loaders.carmen.writer.CarmenWriter` round-trip even when
their scans share timestamps.

A scan outside the poses' time span gets the nearest end pose held, but only
within ``tolerance`` of it (a scan logged a moment before the first ODOM line,
as fr079's first is by 0.01 s); farther out the pose would be invented, not
measured (a log whose ODOM or TRUEPOS stream stops long before its scans do),
so it is a ParseError naming the scan's line, as the bag loader refuses to
extrapolate. ``time_tolerance=inf`` holds the end poses at any distance.

Between the lines the same holds for a gap: a scan whose two bracketing poses
lie more than ``max_gap`` seconds apart (the loader option ``max_pose_gap``,
:data:`~albot1.data.loaders.base.DEFAULT_MAX_POSE_GAP_S`) is a ParseError
naming its line, not a pose interpolated across a stretch nothing recorded.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.data.errors import ParseError
from albot1.data.loaders.base import DEFAULT_MAX_POSE_GAP_S, pose_gap_problem
from albot1.data.loaders.carmen.parse import PoseRecords
from albot1.geometry import se2


class PoseBuffer:
    """Poses of one message kind, sorted by time, trimmed as scans are emitted."""

    def __init__(self, path: Path, kind: str, tolerance: float, max_gap: float = DEFAULT_MAX_POSE_GAP_S) -> None:
        self.path = path
        self.kind = kind
        self.tolerance = tolerance
        self.max_gap = max_gap
        self.times = np.zeros(0)
        self.poses = np.zeros((0, 3))
        self.lines = np.zeros(0, dtype=np.int64)
        self.max_time = -np.inf
        self.min_time = np.inf
        self.max_line = 0
        self.seen = 0

    def feed(self, records: PoseRecords) -> None:
        if len(records.lines) == 0:
            return
        running = np.maximum.accumulate(np.r_[self.max_time, records.timestamps])
        back = running[:-1] - records.timestamps
        if (back > self.tolerance).any():
            i = int(np.argmax(back > self.tolerance))
            hint = (
                " (the ODOM stream restarts after every scan: this looks like a GMapping-corrected log; "
                "use odometry='odom-segments')"
                if self.kind == "ODOM"
                else ""
            )
            raise ParseError(
                self.path,
                f"{self.kind} timestamp {records.timestamps[i]:.6f} goes back "
                f"{back[i]:.3f} s; expected non-decreasing ipc timestamps (tolerance "
                f"{self.tolerance} s){hint}",
                line=int(records.lines[i]),
            )
        times = np.concatenate([self.times, records.timestamps])
        poses = np.concatenate([self.poses, records.poses])
        lines = np.concatenate([self.lines, records.lines])
        order = np.argsort(times, kind="stable")
        self.times, self.poses, self.lines = times[order], poses[order], lines[order]
        self.max_time = float(running[-1])
        self.min_time = min(self.min_time, float(records.timestamps.min()))
        self.max_line = int(records.lines[-1])
        self.seen += len(records.lines)

    def ready(self, t: float) -> bool:
        """Whether no later line can change the pose at ``t``.

        Later stamps lie above ``max_time - tolerance``; beyond ``t + tolerance``
        they cannot land before ``t``. A scan before every pose seen so far waits one
        tolerance longer, until they cannot land within ``tolerance`` after it either,
        so whether it is too far before the first pose (:meth:`at`) does not depend on
        where the log's chunks end.
        """
        wait = 2 * self.tolerance if t < self.min_time else self.tolerance
        return self.max_time > t + wait

    def at(self, t: float, line: int) -> NDArray[np.float64]:
        if len(self.times) == 0:
            raise ParseError(
                self.path,
                f"no {self.kind} line in the log to interpolate the scan's pose from; "
                f"expected {self.kind} lines (or choose another pose source)",
                line=line,
            )
        self._check_span(t, line)
        exact = np.flatnonzero(self.times == t)
        if len(exact):
            # a pose stamped exactly at the scan time is used as is; among several (logs whose stamps
            # repeat), the nearest one before the scan line in the file, else the nearest after it
            lines = self.lines[exact]
            before = lines < line
            pick = exact[np.argmax(np.where(before, lines, -1))] if before.any() else exact[np.argmin(lines)]
            stored: NDArray[np.float64] = self.poses[pick].copy()
            return stored
        after = int(np.searchsorted(self.times, t, side="right"))
        if 0 < after < len(self.times):  # beyond the ends the end pose is held, within tolerance (_check_span)
            problem = pose_gap_problem(t, self.times[after - 1], self.times[after], self.max_gap, f"{self.kind} lines")
            if problem is not None:
                raise ParseError(self.path, problem, line=line)
        blended: NDArray[np.float64] = se2.interpolate(self.times, self.poses, np.array([t]))[0]
        return blended

    def _check_span(self, t: float, line: int) -> None:
        """A ParseError for a scan farther than ``tolerance`` outside the poses' time span (its pose would be held)."""
        if t < self.min_time - self.tolerance:
            where, gap, end = "before the first", self.min_time - t, self.min_time
        elif t > self.max_time + self.tolerance:
            where, gap, end = "after the last", t - self.max_time, self.max_time
        else:
            return
        raise ParseError(
            self.path,
            f"scan at t = {t:.6f} s lies {gap:.3f} s {where} {self.kind} line (t = {end:.6f} s); its pose would "
            f"be invented (the end pose held), not measured; expected "
            f"scans within the {self.kind} lines' time span, to within time_tolerance {self.tolerance} s "
            f"(time_tolerance=inf holds the end poses)",
            line=line,
        )

    def trim(self, oldest_needed: float) -> None:
        """Drop poses older than the bracket of ``oldest_needed - tolerance``."""
        cutoff = oldest_needed - self.tolerance
        below = np.flatnonzero(self.times < cutoff)
        if len(below) > 1:
            keep_from = int(below[-1])
            self.times, self.poses = self.times[keep_from:], self.poses[keep_from:]
            self.lines = self.lines[keep_from:]
