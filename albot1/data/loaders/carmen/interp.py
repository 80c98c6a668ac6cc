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
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.parse import PoseRecords
from albot1.geometry import se2


class PoseBuffer:
    """Poses of one message kind, sorted by time, trimmed as scans are emitted."""

    def __init__(self, path: Path, kind: str, tolerance: float) -> None:
        self.path = path
        self.kind = kind
        self.tolerance = tolerance
        self.times = np.zeros(0)
        self.poses = np.zeros((0, 3))
        self.lines = np.zeros(0, dtype=np.int64)
        self.max_time = -np.inf
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
        self.max_line = int(records.lines[-1])
        self.seen += len(records.lines)

    def ready(self, t: float) -> bool:
        return self.max_time > t + self.tolerance

    def at(self, t: float, line: int) -> NDArray[np.float64]:
        if len(self.times) == 0:
            raise ParseError(
                self.path,
                f"no {self.kind} line in the log to interpolate the scan's pose from; "
                f"expected {self.kind} lines (or choose another pose source)",
                line=line,
            )
        exact = np.flatnonzero(self.times == t)
        if len(exact):
            # a pose stamped exactly at the scan time is used as is; among several (logs whose stamps
            # repeat), the nearest one before the scan line in the file, else the nearest after it
            lines = self.lines[exact]
            before = lines < line
            pick = exact[np.argmax(np.where(before, lines, -1))] if before.any() else exact[np.argmin(lines)]
            stored: NDArray[np.float64] = self.poses[pick].copy()
            return stored
        blended: NDArray[np.float64] = se2.interpolate(self.times, self.poses, np.array([t]))[0]
        return blended

    def trim(self, oldest_needed: float) -> None:
        """Drop poses older than the bracket of ``oldest_needed - tolerance``."""
        cutoff = oldest_needed - self.tolerance
        below = np.flatnonzero(self.times < cutoff)
        if len(below) > 1:
            keep_from = int(below[-1])
            self.times, self.poses = self.times[keep_from:], self.poses[keep_from:]
            self.lines = self.lines[keep_from:]
