"""Sequence -> ROS1 ``.bag`` / ROS2 sqlite3 / ROS2 MCAP bags, through ``rosbags``.

Every frame becomes, all stamped with the scan's timestamp (header stamp and
bag time alike):

* ``/scan`` ``sensor_msgs/LaserScan`` (frame ``laser``): ranges as float32,
  no-return (NaN, or a range of 0 m) as ``+inf`` (REP-117: "no object detected in range"),
  ``range_min = 0``, ``range_max`` = the scan's max range, ``angle_min`` and
  ``angle_increment`` from the beam angles, which must be evenly spaced;
* ``/odom`` ``nav_msgs/Odometry`` (``odom -> base_link``): the odometry pose
  (z = 0, yaw-only quaternion, so the heading comes back wrapped to
  ``(-pi, pi]``);
* ``/ground_truth`` ``nav_msgs/Odometry`` (``map -> base_link``) when the
  frame has a reference pose;
* ``/tf`` ``tf2_msgs/TFMessage``: the odometry pose again as the transform
  ``odom -> base_link``, and once, before the first scan, ``/tf_static``
  ``base_link -> laser`` from the sequence's ``sensor_offset`` (latched in
  ROS1, transient-local QoS in ROS2), so other SLAM systems can replay the
  bag and the reader gets the laser's mount back (:mod:`.mounting`).

A ROS2 bag is a folder; ``rosbags`` names its storage file after the folder
plus the storage suffix, which would turn ``intel.mcap`` into
``intel.mcap/intel.mcap.mcap``. When OUT already ends in the storage's suffix
the file takes OUT's name instead (``intel.mcap/intel.mcap`` beside
``metadata.yaml``); any other OUT keeps rosbags' layout (``run/run.mcap``).

Because odometry is written at exactly the scan stamps, the loader's
interpolation returns the written poses unchanged; this needs strictly
increasing scan stamps, which the writer checks (see ``convert(retime=)``
for logs whose stamps jitter or repeat). Each LaserScan and pose is checked
with the reader's own rules (:func:`.msg.laserscan_problem`, :func:`.msg.reading_problem`, on the float32
values as stored; :func:`.msg.pose_problem`) before it is written, so the
writer never produces a bag its reader refuses. The output must not exist;
a failed write removes what it created (output rules:
:mod:`albot1.data.loaders.output`).
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
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
    ns_text,
    pose_problem,
    quaternion_from_yaw,
    reading_problem,
    seconds_to_ns,
    split_ns,
)
from albot1.data.loaders.rosbag.topics import LASER_SCAN, ODOMETRY, TF_MESSAGE, WRITTEN_REFERENCE
from albot1.data.model import Frame, Sequence, mount_problem

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

SCAN_TOPIC = "/scan"
ODOM_TOPIC = "/odom"
TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"
BASE_FRAME = "base_link"
LASER_FRAME = "laser"
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
        self.Transform, self.TransformStamped = (
            t["geometry_msgs/msg/Transform"],
            t["geometry_msgs/msg/TransformStamped"],
        )
        self.TFMessage = t[TF_MESSAGE]

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
            # no return (NaN, or 0 m: no laser measures its own window) as +inf, never 0: with range_min = 0
            # a 0 would be a valid reading, a point at the laser, for other tools replaying the bag
            returns = np.isfinite(scan.ranges) & (scan.ranges != 0.0)
            ranges = np.where(returns, scan.ranges, np.inf).astype(np.float32)
        lost = returns & (ranges == 0.0)
        if lost.any():
            k = int(np.argmax(lost))
            raise UnwritableError(
                f"scan #{frame.index}: range {k + 1} of {scan.beams} is {float(scan.ranges[k])!r} m, which is 0 as "
                f"float32 and would be read back as no return; expected a return of at least float32's smallest step"
            )
        with np.errstate(over="ignore"):
            angle_min, step = spacing
            fields = [float(np.float32(v)) for v in (angle_min, scan.angles[-1], step, 0.0, scan.max_range)]
        problem = laserscan_problem(scan.beams, *fields) or reading_problem(ranges, fields[3], fields[4])
        if problem is not None:
            raise UnwritableError(f"scan #{frame.index}: LaserScan {problem}; the bag reader would refuse it")
        return self.LaserScan(
            header=self.header(ns, LASER_FRAME, frame.index),
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
            child_frame_id=BASE_FRAME,
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

    def tf(self, pose: np.ndarray, ns: int, parent: str, child: str, seq: int) -> Any:
        """A TFMessage holding the one planar transform ``parent -> child`` (z = 0, yaw-only rotation)."""
        problem = pose_problem(pose)
        if problem is not None:
            raise UnwritableError(f"scan #{seq}: {parent} -> {child} {problem}; the bag reader would refuse it")
        x, y, theta = (float(v) for v in pose)
        qx, qy, qz, qw = quaternion_from_yaw(theta)
        transform = self.TransformStamped(
            header=self.header(ns, parent, seq),
            child_frame_id=child,
            transform=self.Transform(
                translation=self.Vector3(x=x, y=y, z=0.0), rotation=self.Quaternion(x=qx, y=qy, z=qz, w=qw)
            ),
        )
        return self.TFMessage(transforms=[transform])


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
    add: Callable[[str, str, bool], Any],
    write: Callable[[Any, int, bytes | memoryview], None],
) -> None:
    """The shared loop; the reference connection is added on the first frame that has one.

    ``add(topic, msgtype, latched)``: ``latched`` for ``/tf_static``, which is
    written once and must reach a player's late subscribers.

    Scan stamps must strictly increase: a bag orders messages and associates
    poses with scans by time, so equal or backward stamps would reorder
    scans or give two scans one pose on reading.
    """
    scan_conn, odom_conn = add(SCAN_TOPIC, LASER_SCAN, False), add(ODOM_TOPIC, ODOMETRY, False)
    static_conn, tf_conn = add(TF_STATIC_TOPIC, TF_MESSAGE, True), add(TF_TOPIC, TF_MESSAGE, False)
    mount = np.asarray(sequence.metadata.sensor_offset, dtype=np.float64)
    mount_refused = mount_problem((float(mount[0]), float(mount[1]), float(mount[2])))  # the reader's own rule
    if mount_refused is not None:
        raise UnwritableError(mount_refused)
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
                f"scan #{frame.index}: timestamp {ns_text(ns)} s is not after the previous scan's "
                f"{ns_text(previous)} s (stamps on the bag's nanosecond clock); a bag orders scans and matches "
                f"poses by time, so stamps must strictly increase (convert with --retime to shift such scans forward)"
            )
        if previous < 0:
            write(static_conn, ns, serialize(msgs.tf(mount, ns, BASE_FRAME, LASER_FRAME, 0), TF_MESSAGE))
        previous = ns
        write(scan_conn, ns, serialize(msgs.scan(frame, ns), LASER_SCAN))
        write(odom_conn, ns, serialize(msgs.odometry(frame.odometry, ns, "odom", frame.index), ODOMETRY))
        write(tf_conn, ns, serialize(msgs.tf(frame.odometry, ns, "odom", BASE_FRAME, frame.index), TF_MESSAGE))
        if frame.reference is not None:
            ref_conn = ref_conn or add(REFERENCE_TOPIC, ODOMETRY, False)
            write(ref_conn, ns, serialize(msgs.odometry(frame.reference, ns, "map", frame.index), ODOMETRY))
    if previous < 0:
        raise UnwritableError("the sequence has no scans; the bag reader refuses a bag whose scan topic is empty")


def _cleanup(path: Path, staging: Path | None = None) -> None:
    if staging is not None:
        shutil.rmtree(staging, ignore_errors=True)
    if path.is_dir():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)


def _latched_qos() -> Any:
    """ROS2's ``transient_local`` profile: what ``/tf_static`` publishers offer, so a late subscriber gets it."""
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )

    zero = QosTime(sec=0, nsec=0)
    return Qos(
        QosHistory.KEEP_LAST,
        1,
        QosReliability.RELIABLE,
        QosDurability.TRANSIENT_LOCAL,
        zero,
        zero,
        QosLiveliness.AUTOMATIC,
        zero,
        False,
    )


def _write_bag(
    sequence: Sequence, path: Path, open_bag: Callable[[Path], Any], ts: Typestore, *, ros1: bool, stem: str
) -> None:
    """Write every frame through a ``rosbags`` writer; a failed write removes what it created.

    ``stem``: the name rosbags' ROS2 writer should see, which it gives the
    storage file; when it differs from ``path.name`` the bag is written in a
    hidden staging folder beside ``path`` and moved to ``path`` once complete.
    """
    from rosbags.rosbag1 import WriterError as Ros1WriterError
    from rosbags.rosbag2 import WriterError as Ros2WriterError

    serialize = ts.serialize_ros1 if ros1 else ts.serialize_cdr
    latched = None if ros1 else [_latched_qos()]

    def connect(bag: Any, topic: str, msgtype: str, latch: bool) -> Any:
        if ros1:
            return bag.add_connection(topic, msgtype, typestore=ts, latching=1 if latch else None)
        return bag.add_connection(topic, msgtype, typestore=ts, offered_qos_profiles=latched if latch else ())

    prepare_output(path)
    staging = Path(tempfile.mkdtemp(prefix=f".{path.name}.", dir=path.parent)) if stem != path.name else None
    target = path if staging is None else staging / stem
    try:
        with writing(path):
            with open_bag(target) as bag:
                _write_frames(
                    sequence,
                    RosMessages(ts, ros1=ros1),
                    serialize,
                    lambda topic, msgtype, latch: connect(bag, topic, msgtype, latch),
                    bag.write,
                )
            if staging is not None:
                os.replace(target, path)
                staging.rmdir()
    except (Ros1WriterError, Ros2WriterError) as exc:
        _cleanup(path, staging)
        raise WriteError(f"{path}: cannot be written: {' '.join(str(exc).split())}") from exc
    except UnwritableError as exc:
        _cleanup(path, staging)
        raise UnwritableError(f"{path}: {exc}") from None
    except BaseException:
        _cleanup(path, staging)
        raise


#: ``tf2_msgs/TFMessage`` as ROS defines it; rosbags' Noetic store lacks the type, so the ROS1 writer adds it.
TF_MESSAGE_DEFINITION = "geometry_msgs/TransformStamped[] transforms"


def _with_tf(ts: Typestore) -> Typestore:
    from rosbags.typesys import get_types_from_msg

    if TF_MESSAGE not in ts.types:
        ts.register(get_types_from_msg(TF_MESSAGE_DEFINITION, TF_MESSAGE))
    return ts


class Ros1BagWriter:
    """A ROS1 bag (format 2.0, uncompressed) with ROS Noetic message definitions."""

    format_name: ClassVar[str] = "ros1"

    def write(self, sequence: Sequence, path: Path) -> None:
        from rosbags.rosbag1 import Writer
        from rosbags.typesys import Stores, get_typestore

        path = Path(path)
        _write_bag(sequence, path, Writer, _with_tf(get_typestore(Stores.ROS1_NOETIC)), ros1=True, stem=path.name)


class _Ros2Writer:
    """A ROS2 bag folder (rosbag2 metadata version 9) with ROS Humble message definitions."""

    format_name: ClassVar[str]
    storage: ClassVar[str]

    def write(self, sequence: Sequence, path: Path) -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer
        from rosbags.typesys import Stores, get_typestore

        path = Path(path)
        plugin = StoragePlugin.MCAP if self.storage == "mcap" else StoragePlugin.SQLITE3
        suffix = ".mcap" if self.storage == "mcap" else ".db3"
        _write_bag(
            sequence,
            path,
            lambda target: Writer(target, version=9, storage_plugin=plugin),
            get_typestore(Stores.ROS2_HUMBLE),
            ros1=False,
            stem=path.stem if path.suffix == suffix else path.name,
        )


class Ros2Sqlite3Writer(_Ros2Writer):
    """ROS2 bag folder with sqlite3 (``.db3``) storage."""

    format_name: ClassVar[str] = "ros2-sqlite3"
    storage: ClassVar[str] = "sqlite3"


class Ros2McapWriter(_Ros2Writer):
    """ROS2 bag folder with MCAP storage."""

    format_name: ClassVar[str] = "ros2-mcap"
    storage: ClassVar[str] = "mcap"
