"""Arbitrary ROS message field values (LaserScan geometry and ranges, Odometry and TF poses, stamps),
stored in real (ROS2 sqlite3) bags with rosbags: the bag loader raises only the project's DataErrors, and what it
does return keeps the data model's promises (finite poses, ascending angles, ranges NaN or >= 0)."""

from __future__ import annotations

import functools
import math
import shutil
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.loaders.rosbag.loader import Ros2BagLoader

ANY_FLOAT = st.one_of(
    st.floats(-10.0, 10.0),
    st.sampled_from([0.0, -0.0, math.nan, math.inf, -math.inf, 1e-30, 1e30, -1e30, math.pi, 2 * math.pi]),
)
STEP = math.radians(1.0)


@st.composite
def laser_fields(draw: st.DrawFn) -> dict[str, Any]:
    n = draw(st.sampled_from([0, 1, 2, 90, 180, 181, 400]))
    fields: dict[str, Any] = {
        "angle_min": -math.pi / 2,
        "angle_max": -math.pi / 2 + 179 * STEP,
        "angle_increment": STEP,
        "range_min": 0.0,
        "range_max": 30.0,
    }
    for key in draw(st.sets(st.sampled_from(sorted(fields)), max_size=3)):
        fields[key] = draw(ANY_FLOAT)
    values = draw(st.sampled_from(["plain", "odd"]))
    ranges = np.full(n, 2.0, np.float32)
    if values == "odd" and n:
        ranges[: min(n, 5)] = draw(st.lists(ANY_FLOAT, min_size=min(n, 5), max_size=min(n, 5)))
    fields["ranges"] = ranges
    return fields


QUATERNION = st.one_of(
    st.just((0.0, 0.0, 0.0, 1.0)),
    st.tuples(ANY_FLOAT, ANY_FLOAT, ANY_FLOAT, ANY_FLOAT),
)


@functools.cache
def humble_typestore() -> Any:
    """One type store for every example: a fresh one compiles each message's serializer again (a tenth of the
    test's time), and a store holds nothing of the bags written with it."""
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE)


def write_bag(
    path: Path, scans: list[dict[str, Any]], poses: list[tuple[Any, ...]], stamps: list[int], tf: bool
) -> None:
    from rosbags.rosbag2 import Writer

    ts = humble_typestore()
    t = ts.types

    def header(sec: int, frame: str = "odom") -> Any:
        return t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](sec=sec, nanosec=0), frame_id=frame)

    with Writer(path, version=9) as bag:
        scan_conn = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        pose_type = "tf2_msgs/msg/TFMessage" if tf else "nav_msgs/msg/Odometry"
        pose_conn = bag.add_connection("/tf" if tf else "/odom", pose_type, typestore=ts)
        for fields, (x, q), sec in zip(scans, poses, stamps, strict=True):
            scan = t["sensor_msgs/msg/LaserScan"](
                header=header(sec, "laser"),
                time_increment=0.0,
                scan_time=0.0,
                intensities=np.zeros(0, np.float32),
                **fields,
            )
            bag.write(scan_conn, sec * 10**9, ts.serialize_cdr(scan, "sensor_msgs/msg/LaserScan"))
            rotation = t["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3])
            if tf:
                transform = t["geometry_msgs/msg/TransformStamped"](
                    header=header(sec),
                    child_frame_id="base_link",
                    transform=t["geometry_msgs/msg/Transform"](
                        translation=t["geometry_msgs/msg/Vector3"](x=x, y=0.0, z=0.0), rotation=rotation
                    ),
                )
                message = t["tf2_msgs/msg/TFMessage"](transforms=[transform])
            else:
                zero = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
                message = t["nav_msgs/msg/Odometry"](
                    header=header(sec),
                    child_frame_id="base_link",
                    pose=t["geometry_msgs/msg/PoseWithCovariance"](
                        pose=t["geometry_msgs/msg/Pose"](
                            position=t["geometry_msgs/msg/Point"](x=x, y=0.0, z=0.0), orientation=rotation
                        ),
                        covariance=np.zeros(36),
                    ),
                    twist=t["geometry_msgs/msg/TwistWithCovariance"](
                        twist=t["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
                    ),
                )
            bag.write(pose_conn, sec * 10**9, ts.serialize_cdr(message, pose_type))


@pytest.mark.slow
@settings(max_examples=50, deadline=None)
@given(
    scans=st.lists(laser_fields(), min_size=1, max_size=3),
    data=st.data(),
    tf=st.booleans(),
    outside=st.sampled_from(["error", "drop"]),
)
def test_arbitrary_field_values_give_frames_or_a_data_error(
    scans: list[dict[str, Any]], data: st.DataObject, tf: bool, outside: str
) -> None:
    n = len(scans)
    poses = data.draw(st.lists(st.tuples(ANY_FLOAT, QUATERNION), min_size=n, max_size=n))
    stamps = data.draw(st.lists(st.sampled_from([0, 5, 10, 11, 12, 2_000_000_000]), min_size=n, max_size=n))
    folder = Path(tempfile.mkdtemp(prefix="albot1-bagfields-"))
    try:
        path = folder / "bag"
        write_bag(path, scans, poses, stamps, tf)
        try:
            for frame in Ros2BagLoader().load(path, outside_odometry=outside).frames():
                assert np.isfinite(frame.odometry).all()
                assert frame.scan.beams > 0 and np.all(np.diff(frame.scan.angles) > 0)
                valid = frame.scan.ranges[~np.isnan(frame.scan.ranges)]
                assert np.all(valid >= 0) and np.all(valid <= frame.scan.max_range)
        except DataError:
            pass
    finally:
        shutil.rmtree(folder, ignore_errors=True)
