"""Bags as recorders write them beyond what ``albot1 convert`` writes: compressed ROS1 chunks (bz2, lz4), ROS2
bags compressed per file or per message (zstd), in sqlite3 or MCAP storage. Each loads the same frames as the
uncompressed bag, and a file-compressed MCAP bag (``run.mcap.zstd``) is named MCAP, not sqlite3."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from albot1.data.loaders.registry import load

RANGES = np.array([1.0, np.inf, 2.5, np.nan, 0.05, 3.0], dtype=np.float32)


def _messages(ts: Any, ros1: bool) -> list[tuple[str, str, int, Any]]:
    """(topic, type, bag time ns, message): three scans of a clockwise scanner and odometry at their stamps."""
    t = ts.types
    out = []
    for k in range(3):
        stamp = t["builtin_interfaces/msg/Time"](sec=10 + k, nanosec=0)

        def header(frame: str, stamp: Any = stamp) -> Any:
            return t["std_msgs/msg/Header"](**({"seq": 0} if ros1 else {}), stamp=stamp, frame_id=frame)

        scan = t["sensor_msgs/msg/LaserScan"](
            header=header("laser"), angle_min=0.5, angle_max=0.5 - 5 * 0.2, angle_increment=-0.2,
            time_increment=0.0, scan_time=0.0, range_min=0.1, range_max=30.0, ranges=RANGES,
            intensities=np.arange(6, dtype=np.float32),
        )  # fmt: skip
        zero = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
        pose = t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=0.5 * k, y=0.0, z=0.0),
            orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        )
        odom = t["nav_msgs/msg/Odometry"](
            header=header("odom"), child_frame_id="base_link",
            pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
            twist=t["geometry_msgs/msg/TwistWithCovariance"](
                twist=t["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
            ),
        )  # fmt: skip
        ns = (10 + k) * 10**9
        out += [("/scan", "sensor_msgs/msg/LaserScan", ns, scan), ("/odom", "nav_msgs/msg/Odometry", ns, odom)]
    return out


def _ros1(path: Path, compression: str | None) -> Path:
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    writer = Writer(path)
    if compression is not None:
        writer.set_compression(Writer.CompressionFormat[compression])
    with writer as bag:
        conns: dict[str, Any] = {}
        for topic, msgtype, ns, msg in _messages(ts, ros1=True):
            conn = conns.get(topic) or conns.setdefault(topic, bag.add_connection(topic, msgtype, typestore=ts))
            bag.write(conn, ns, ts.serialize_ros1(msg, msgtype))
    return path


def _ros2(path: Path, storage: str, mode: str | None) -> Path:
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    writer = Writer(path, version=9, storage_plugin=StoragePlugin[storage])
    if mode is not None:
        writer.set_compression(CompressionMode[mode], CompressionFormat.ZSTD)
    with writer as bag:
        conns: dict[str, Any] = {}
        for topic, msgtype, ns, msg in _messages(ts, ros1=False):
            conn = conns.get(topic) or conns.setdefault(topic, bag.add_connection(topic, msgtype, typestore=ts))
            bag.write(conn, ns, ts.serialize_cdr(msg, msgtype))
    return path


def _check(path: Path) -> str:
    seq = load(str(path))
    frames = list(seq.frames())
    assert len(frames) == 3
    for k, frame in enumerate(frames):
        np.testing.assert_array_equal(frame.odometry, [0.5 * k, 0.0, 0.0])
        # by hand: beam i at 0.5 - 0.2 i (float32 fields), reversed to ascend; inf, NaN, below range_min -> NaN
        a0, step = float(np.float32(0.5)), float(np.float32(-0.2))
        assert frame.scan.angles.tolist() == [a0 + i * step for i in range(6)][::-1]
        np.testing.assert_array_equal(frame.scan.ranges, [3.0, np.nan, np.nan, 2.5, np.nan, 1.0])
    return seq.metadata.format


@pytest.mark.parametrize("compression", [None, "BZ2", "LZ4"])
def test_compressed_ros1_bags_load_the_same_frames(tmp_path: Path, compression: str | None) -> None:
    assert _check(_ros1(tmp_path / "run.bag", compression)) == "ros1"


@pytest.mark.parametrize("storage", ["SQLITE3", "MCAP"])
@pytest.mark.parametrize("mode", [None, "FILE", "MESSAGE"])
def test_compressed_ros2_bags_load_the_same_frames_and_name_their_storage(
    tmp_path: Path, storage: str, mode: str | None
) -> None:
    bag = _ros2(tmp_path / "run", storage, mode)
    assert _check(bag) == f"ros2-{storage.lower()}"
