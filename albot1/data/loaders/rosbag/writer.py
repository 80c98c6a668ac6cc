"""Sequence -> ROS1 ``.bag`` / ROS2 sqlite3 / ROS2 MCAP bags, through ``rosbags``.

Every frame becomes, all stamped with the scan's timestamp (header stamp and
bag time alike):

* ``/scan`` ``sensor_msgs/LaserScan`` (frame ``laser``): ranges as float32,
  no-return (NaN) as ``+inf`` (REP-117: "no object detected in range"),
  ``range_min = 0``, ``range_max`` = the scan's max range, ``angle_min`` and
  ``angle_increment`` from the beam angles, which must be evenly spaced;
* ``/odom`` ``nav_msgs/Odometry`` (``odom -> base_link``): the odometry pose
  (z = 0, yaw-only quaternion, so the heading comes back wrapped to
  ``(-pi, pi]``);
* ``/ground_truth`` ``nav_msgs/Odometry`` (``map -> base_link``) when the
  frame has a reference pose.

Because odometry is written at exactly the scan stamps, the loader's
interpolation returns the written poses unchanged; this needs strictly
increasing scan stamps, which the writer checks (see ``convert(retime=)``
for logs whose stamps jitter or repeat). Each LaserScan and pose is checked
with the reader's own rules (:func:`.msg.laserscan_problem`, on the float32
values as stored; :func:`.msg.pose_problem`) before it is written, so the
writer never produces a bag its reader refuses. The output must not exist;
a failed write removes what it created (output rules:
:mod:`albot1.data.loaders.output`).
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from albot1.data.errors import UnwritableError, WriteError
from albot1.data.loaders.base import reference_presence_problem
from albot1.data.loaders.beams import even_spacing
from albot1.data.loaders.output import prepare_output, writing
from albot1.data.loaders.rosbag.msg import (
    laserscan_problem,
    pose_problem,
    quaternion_from_yaw,
    seconds_to_ns,
    split_ns,
)
from albot1.data.loaders.rosbag.topics import LASER_SCAN, ODOMETRY, WRITTEN_REFERENCE
from albot1.data.model import Frame, Sequence

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

SCAN_TOPIC = "/scan"
ODOM_TOPIC = "/odom"
REFERENCE_TOPIC = WRITTEN_REFERENCE


class RosMessages:
    """Builds the three message kinds of one frame with one typestore (ROS1 and ROS2 differ only in Header)."""

    def __init__(self, typestore: Typestore, ros1: bool) -> None:
        self.ros1 = ros1
        t = typestore.types
        self.Time, self.Header = t["builtin_interfaces/msg/Time"], t["std_msgs/msg/Header"]
        self.LaserScan, self.Odometry = t[LASER_SCAN], t[ODOMETRY]
        self.Pose, self.PoseWithCovariance = t["geometry_msgs/msg/Pose"], t["geometry_msgs/msg/PoseWithCovariance"]
        self.Point, self.Quaternion = t["geometry_msgs/msg/Point"], t["geometry_msgs/msg/Quaternion"]
        self.Twist, self.TwistWithCovariance = t["geometry_msgs/msg/Twist"], t["geometry_msgs/msg/TwistWithCovariance"]
        self.Vector3 = t["geometry_msgs/msg/Vector3"]

    def header(self, ns: int, frame_id: str, seq: int) -> Any:
        sec, nanosec = split_ns(ns)
        stamp = self.Time(sec=sec, nanosec=nanosec)
        if self.ros1:
            return self.Header(seq=seq, stamp=stamp, frame_id=frame_id)
        return self.Header(stamp=stamp, frame_id=frame_id)

    def scan(self, frame: Frame, ns: int) -> Any:
        scan = frame.scan
        if not np.isfinite(scan.angles).all():
            raise UnwritableError(f"scan #{frame.index}: beam angles must be finite numbers (radians)")
        spacing = even_spacing(scan.angles)
        if spacing is None:
            raise UnwritableError(
                f"scan #{frame.index}: beam angles are not evenly spaced, which a LaserScan message cannot represent"
            )
        finite = scan.ranges[np.isfinite(scan.ranges)]
        if finite.size and (finite.min() < 0 or finite.max() > scan.max_range):
            raise UnwritableError(
                f"scan #{frame.index}: ranges must lie in [0, max_range={scan.max_range}] m, got "
                f"[{finite.min()}, {finite.max()}]; they would be read back as no-return"
            )
        with np.errstate(over="ignore"):  # beyond float32: inf, refused below or read as no return
            ranges = np.where(np.isfinite(scan.ranges), scan.ranges, np.inf).astype(np.float32)
            angle_min, step = spacing
            fields = [float(np.float32(v)) for v in (angle_min, scan.angles[-1], step, 0.0, scan.max_range)]
        problem = laserscan_problem(scan.beams, *fields)
        if problem is not None:
            raise UnwritableError(f"scan #{frame.index}: LaserScan {problem}; the bag reader would refuse it")
        return self.LaserScan(
            header=self.header(ns, "laser", frame.index),
            angle_min=angle_min,
            angle_max=float(scan.angles[-1]),
            angle_increment=step,
            time_increment=0.0,
            scan_time=0.0,
            range_min=0.0,
            range_max=float(scan.max_range),
            ranges=ranges,
            intensities=np.zeros(0, dtype=np.float32),
        )

    def odometry(self, pose: np.ndarray, ns: int, parent: str, seq: int) -> Any:
        problem = pose_problem(pose)
        if problem is not None:
            raise UnwritableError(f"scan #{seq}: {parent} {problem}; the bag reader would refuse it")
        x, y, theta = (float(v) for v in pose)
        qx, qy, qz, qw = quaternion_from_yaw(theta)
        zero = self.Vector3(x=0.0, y=0.0, z=0.0)
        return self.Odometry(
            header=self.header(ns, parent, seq),
            child_frame_id="base_link",
            pose=self.PoseWithCovariance(
                pose=self.Pose(
                    position=self.Point(x=x, y=y, z=0.0), orientation=self.Quaternion(x=qx, y=qy, z=qz, w=qw)
                ),
                covariance=np.zeros(36, dtype=np.float64),
            ),
            twist=self.TwistWithCovariance(
                twist=self.Twist(linear=zero, angular=zero), covariance=np.zeros(36, dtype=np.float64)
            ),
        )


#: ROS 2 stores the seconds of a time stamp as int32 (ROS 1 as uint32): the common range.
_MAX_ROS_SECONDS = 2**31 - 1


def _frame_ns(frame: Frame) -> int:
    t = frame.scan.timestamp
    if not (math.isfinite(t) and 0 <= t < _MAX_ROS_SECONDS):
        raise UnwritableError(
            f"scan #{frame.index}: timestamp {t} s cannot be a ROS time (expected 0 <= t < {_MAX_ROS_SECONDS} s)"
        )
    return seconds_to_ns(t)


def _write_frames(
    sequence: Sequence,
    msgs: RosMessages,
    serialize: Callable[[Any, str], bytes | memoryview],
    add: Callable[[str, str], Any],
    write: Callable[[Any, int, bytes | memoryview], None],
) -> None:
    """The shared loop; the reference connection is added on the first frame that has one.

    Scan stamps must strictly increase: a bag orders messages and associates
    poses with scans by time, so equal or backward stamps would reorder
    scans or give two scans one pose on reading.
    """
    scan_conn, odom_conn = add(SCAN_TOPIC, LASER_SCAN), add(ODOM_TOPIC, ODOMETRY)
    ref_conn = None
    previous = -1
    first: Frame | None = None
    for frame in sequence.frames():
        first = first or frame
        gap = reference_presence_problem(first, frame, f"a bag ({REFERENCE_TOPIC})")
        if gap is not None:
            raise UnwritableError(gap)
        ns = _frame_ns(frame)
        if ns <= previous:
            raise UnwritableError(
                f"scan #{frame.index}: timestamp {frame.scan.timestamp!r} s is not after the previous "
                f"scan's ({previous * 1e-9!r} s); a bag orders scans and matches poses by time, so "
                f"stamps must strictly increase (convert with --retime to shift such scans forward)"
            )
        previous = ns
        write(scan_conn, ns, serialize(msgs.scan(frame, ns), LASER_SCAN))
        write(odom_conn, ns, serialize(msgs.odometry(frame.odometry, ns, "odom", frame.index), ODOMETRY))
        if frame.reference is not None:
            ref_conn = ref_conn or add(REFERENCE_TOPIC, ODOMETRY)
            write(ref_conn, ns, serialize(msgs.odometry(frame.reference, ns, "map", frame.index), ODOMETRY))
    if previous < 0:
        raise UnwritableError("the sequence has no scans; the bag reader refuses a bag whose scan topic is empty")


def _cleanup(path: Path) -> None:
    if path.is_dir():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)


def _write_bag(sequence: Sequence, path: Path, open_bag: Callable[[], Any], ts: Typestore, *, ros1: bool) -> None:
    """Write every frame through a ``rosbags`` writer; a failed write removes what it created."""
    from rosbags.rosbag1 import WriterError as Ros1WriterError
    from rosbags.rosbag2 import WriterError as Ros2WriterError

    serialize = ts.serialize_ros1 if ros1 else ts.serialize_cdr
    prepare_output(path)
    try:
        with writing(path), open_bag() as bag:
            _write_frames(
                sequence,
                RosMessages(ts, ros1=ros1),
                serialize,
                lambda topic, msgtype: bag.add_connection(topic, msgtype, typestore=ts),
                bag.write,
            )
    except (Ros1WriterError, Ros2WriterError) as exc:
        _cleanup(path)
        raise WriteError(f"{path}: cannot be written: {' '.join(str(exc).split())}") from exc
    except UnwritableError as exc:
        _cleanup(path)
        raise UnwritableError(f"{path}: {exc}") from None
    except BaseException:
        _cleanup(path)
        raise


class Ros1BagWriter:
    """A ROS1 bag (format 2.0, uncompressed) with ROS Noetic message definitions."""

    format_name: ClassVar[str] = "ros1"

    def write(self, sequence: Sequence, path: Path) -> None:
        from rosbags.rosbag1 import Writer
        from rosbags.typesys import Stores, get_typestore

        path = Path(path)
        _write_bag(sequence, path, lambda: Writer(path), get_typestore(Stores.ROS1_NOETIC), ros1=True)


class _Ros2Writer:
    """A ROS2 bag folder (rosbag2 metadata version 9) with ROS Humble message definitions."""

    format_name: ClassVar[str]
    storage: ClassVar[str]

    def write(self, sequence: Sequence, path: Path) -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer
        from rosbags.typesys import Stores, get_typestore

        path = Path(path)
        plugin = StoragePlugin.MCAP if self.storage == "mcap" else StoragePlugin.SQLITE3
        _write_bag(
            sequence,
            path,
            lambda: Writer(path, version=9, storage_plugin=plugin),
            get_typestore(Stores.ROS2_HUMBLE),
            ros1=False,
        )


class Ros2Sqlite3Writer(_Ros2Writer):
    """ROS2 bag folder with sqlite3 (``.db3``) storage."""

    format_name: ClassVar[str] = "ros2-sqlite3"
    storage: ClassVar[str] = "sqlite3"


class Ros2McapWriter(_Ros2Writer):
    """ROS2 bag folder with MCAP storage."""

    format_name: ClassVar[str] = "ros2-mcap"
    storage: ClassVar[str] = "mcap"
