"""The poses of each CARMEN scan: the odometry and reference sources, and the corrected logs' anchors.

A scan's odometry comes from its own line (``laser-pose``), from the ODOM
lines interpolated at its time (``odom``), or, in the GMapping-corrected logs
of ``radish-corrected/``, from the ODOM increments since the previous scan
re-anchored at each corrected scan pose (``odom-segments``); its reference
from TRUEPOS lines (``truepos``) or its line's pose fields (``laser-pose``).
:class:`PoseSources` holds the look-ahead buffers these need across chunks
(:mod:`.interp`) and says when a waiting scan can be given its poses.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from albot1.data.errors import DataError, ParseError
from albot1.data.loaders.carmen.interp import PoseBuffer
from albot1.data.loaders.carmen.options import CarmenOptions
from albot1.data.loaders.carmen.parse import OLD_LASERS, ParsedChunk
from albot1.data.model import Scan
from albot1.geometry import se2

#: The corrected logs print anchors with the same digits as the scan pose; this only absorbs float noise.
ANCHOR_TOLERANCE = 1e-5


@dataclass(slots=True)
class PendingScan:
    """A decoded scan waiting for its poses (ODOM/TRUEPOS look-ahead)."""

    line: int
    timestamp: float
    scan: Scan
    sensor: np.ndarray | None
    robot: np.ndarray | None


class PoseSources:
    """The odometry and reference of each scan, from the sources the options chose (state of one pass)."""

    def __init__(self, path: Path, opts: CarmenOptions, laser: str, reference: str) -> None:
        self.path = path
        self.mode = opts.odometry
        self.laser = laser
        self.reference_mode = reference
        tol = opts.time_tolerance
        self.odom = PoseBuffer(path, "ODOM", tol) if opts.odometry == "odom" else None
        self.truth = PoseBuffer(path, "TRUEPOS", tol) if reference == "truepos" else None
        #: pose messages no source reads: the parser need not decode them
        self.skip = frozenset(
            name
            for name, used in (("ODOM", opts.odometry != "laser-pose"), ("TRUEPOS", self.truth is not None))
            if not used
        )
        # odom-segments state
        self.seg_lines = np.zeros(0, dtype=np.int64)
        self.seg_poses = np.zeros((0, 3))
        self.prev_scan: tuple[int, np.ndarray, np.ndarray] | None = None  # line, logged pose, odometry

    @property
    def look_ahead(self) -> bool:
        """Whether a scan may have to wait for later pose lines (ODOM or TRUEPOS interpolation)."""
        return self.odom is not None or self.truth is not None

    def feed(self, parsed: ParsedChunk) -> None:
        """Take the pose lines of one chunk."""
        if self.odom is not None:
            self.odom.feed(parsed.odom)
        if self.truth is not None:
            self.truth.feed(parsed.truepos)
        if self.mode == "odom-segments":
            self.seg_lines = np.concatenate([self.seg_lines, parsed.odom.lines])
            self.seg_poses = np.concatenate([self.seg_poses, parsed.odom.poses])

    def ready(self, stamp: float) -> bool:
        """Whether a scan at ``stamp`` can be given its poses (no later line can change them)."""
        return all(buf is None or buf.ready(stamp) for buf in (self.odom, self.truth))

    def trim(self, oldest: float) -> None:
        """Drop the buffered poses no scan at or after ``oldest`` can need."""
        for buf in (self.odom, self.truth):
            if buf is not None:
                buf.trim(oldest)

    def odometry(self, rec: PendingScan) -> np.ndarray:
        """The odometry of a scan (in file order: ``odom-segments`` carries state from one scan to the next)."""
        mode = self.mode
        if mode == "laser-pose":
            assert rec.robot is not None  # RAWLASER + laser-pose is rejected in load()
            return rec.robot.copy()
        if mode == "odom":
            assert self.odom is not None
            return self.odom.at(rec.timestamp, rec.line)
        return self._segment_odometry(rec)

    def reference(self, rec: PendingScan) -> np.ndarray | None:
        """The reference pose of a scan, or None without a reference source."""
        if self.reference_mode == "none":
            return None
        if self.reference_mode == "truepos":
            assert self.truth is not None
            return self.truth.at(rec.timestamp, rec.line)
        pose = rec.sensor if self.laser in OLD_LASERS else rec.robot
        assert pose is not None
        return pose.copy()

    def _segment_odometry(self, rec: PendingScan) -> np.ndarray:
        logged = rec.sensor if self.laser in OLD_LASERS else rec.robot
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
            if gap > ANCHOR_TOLERANCE:
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
