"""The poses of each CARMEN scan: the odometry and reference sources, and the corrected logs' anchors.

A scan's odometry comes from its own line (``laser-pose``), from the ODOM
lines interpolated at its time (``odom``), or, in the GMapping-corrected logs
of ``radish-corrected/``, from the ODOM increments since the previous scan
re-anchored at each corrected scan pose (``odom-segments``); its reference
from TRUEPOS lines (``truepos``) or its line's pose fields (``laser-pose``).

Robot, not laser: in CARMEN a laser line's ``x y theta`` (FLASER/RLASER) and
``laser_x laser_y laser_theta`` (ROBOTLASER1) are the *laser's* pose, the
robot pose composed with the laser's mount (CARMEN's ``robot_laser.c`` writes
``x = odom_x + offset cos(theta)``, ``theta = odom_theta (+ pi for the rear
laser)``; its scan matcher ``vasco`` corrects that field, not the robot pose).
The reference is the robot's, so those fields are composed with the inverse
mount; so is the ``odom-segments`` chain, which starts at the FLASER pose
field. The odometry fields (``odom_x ...``, ``robot_x ...``) are robot poses
already and are taken as logged, except where a FLASER/RLASER line holds the
same numbers in both field sets (the corrected logs write their one corrected
pose twice): those are the laser's pose, like the reference.
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
#: Largest accepted disagreement of a ROBOTLASER1 line's mount with the first line's (m and rad): CARMEN prints
#: poses with 6 decimals, which moves ``between(robot pose, laser pose)`` by ~1e-6 (fr-clinic: 1.3e-6 m, 0 rad).
MOUNT_TOLERANCE = 1e-4


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

    def __init__(
        self, path: Path, opts: CarmenOptions, laser: str, reference: str, mount: tuple[float, float, float]
    ) -> None:
        self.path = path
        #: the laser's pose on the robot (``metadata.sensor_offset``); None when zero (poses kept bit for bit)
        self.unmount = se2.inverse(np.asarray(mount, dtype=np.float64)) if any(mount) else None
        self.mode = opts.odometry
        self.laser = laser
        self.reference_mode = reference
        tol = opts.time_tolerance
        gap = opts.max_pose_gap
        self.odom = PoseBuffer(path, "ODOM", tol, gap) if opts.odometry == "odom" else None
        self.truth = PoseBuffer(path, "TRUEPOS", tol, gap) if reference == "truepos" else None
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
            if self.laser in OLD_LASERS and rec.sensor is not None and np.array_equal(rec.sensor, rec.robot):
                # A corrected log writes its one corrected pose in both field sets (raw CARMEN lines differ by
                # the mount): that is the laser's pose, read as the reference is, so perfect odometry stays the
                # reference to the bit instead of sitting one mount away from it.
                return self._robot(rec.robot)
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
        assert rec.sensor is not None  # RAWLASER + laser-pose is rejected in load()
        return self._robot(rec.sensor)

    def _robot(self, laser_pose: np.ndarray) -> np.ndarray:
        """The robot's pose from the laser's: ``laser_pose * inv(mount)``."""
        if self.unmount is None:
            return np.array(laser_pose, dtype=np.float64)
        robot: np.ndarray = se2.compose(laser_pose, self.unmount)
        return robot

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
        # the chain lives in the frame of the logged pose, the laser's for FLASER/RLASER (see the module docstring)
        return self._robot(odometry) if self.laser in OLD_LASERS else odometry


def mount_problem(
    robot: np.ndarray, laser: np.ndarray, mount: tuple[float, float, float], message: str = "ROBOTLASER1"
) -> tuple[int, str] | None:
    """The first ROBOTLASER1 (or ``message``: ROBOTLASER2) row whose own mount is not ``mount``, and why.

    A row's own mount is ``between(robot pose, laser pose)``.

    The loader takes the mount from the log's first line and applies it to every scan; a later line whose
    laser sits elsewhere on the robot would be placed wrongly without a word (a second laser's lines under
    one name, a changed mount, or laser poses corrected by a scan matcher apart from the robot poses).
    """
    found = se2.between(robot, laser)
    gap = np.abs(found - np.asarray(mount, dtype=np.float64))
    gap[:, 2] = np.abs(se2.wrap(gap[:, 2]))
    bad = np.flatnonzero((gap > MOUNT_TOLERANCE).any(axis=1))
    if not len(bad):
        return None
    row = int(bad[0])
    shown = ", ".join(f"{v:.6g}" for v in found[row])
    expected = ", ".join(f"{v:.6g}" for v in mount)
    return row, (
        f"{message} laser pose vs robot pose puts the laser at ({shown}) (x m, y m, yaw rad) on the robot, but the "
        f"log's first {message} line puts it at ({expected}); expected one mount for every line (to within "
        f"{MOUNT_TOLERANCE:g}): the loader applies one mount to every scan, so lines of another laser or whose laser "
        f"poses were corrected apart from the robot poses cannot be read as this log's scans (a corrected log "
        f"reads when its PARAM robot_{'rear' if message == 'ROBOTLASER2' else 'front'}laser_offset states the mount)"
    )
