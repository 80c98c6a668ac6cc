"""Issue 15, bags: LaserScans whose range count disagrees with their angles, zero quaternions, empty
topics, ROS2 folders without metadata.yaml and damaged or old ROS1 bags are one-line errors."""

from __future__ import annotations

import math
import struct
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from albot1.data.errors import DataError, ParseError, TopicError, UnwritableError
from albot1.data.loaders.registry import load
from albot1.data.loaders.rosbag.bag1_check import damage, version_problem
from albot1.data.loaders.rosbag.loader import Ros1BagLoader
from albot1.data.loaders.rosbag.msg import (
    laserscan_problem,
    quaternion_problem,
    reading_problem,
    yaw_from_quaternion,
)
from albot1.data.loaders.rosbag.writer import Ros1BagWriter
from albot1.data.model import Frame, Scan, Sequence

STEP = math.radians(1.0)


def write_bag(
    path: Path,
    scans: list[dict[str, Any]],
    quaternions: list[tuple[float, float, float, float]] | None = None,
    *,
    odom_offset_s: int = 0,
    odom_children: list[str] | None = None,
) -> Path:
    """A ROS1 bag written with rosbags directly, so any field value can be stored."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    t = ts.types

    def header(i: int, frame_id: str = "x") -> Any:
        return t["std_msgs/msg/Header"](
            seq=i, stamp=t["builtin_interfaces/msg/Time"](sec=10 + i, nanosec=0), frame_id=frame_id
        )

    with Writer(path) as bag:
        scan_conn = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        odom_conn = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        for i, given in enumerate(scans):
            fields = dict(given)
            frame_id = str(fields.pop("frame_id", "x"))  # the scan's header frame (the laser), not a message field
            values = {
                "angle_min": -math.pi / 2,
                "angle_max": -math.pi / 2 + 179 * STEP,
                "angle_increment": STEP,
                "range_min": 0.0,
                "range_max": 30.0,
                "ranges": np.full(180, 2.0, np.float32),
                **fields,
            }
            msg = t["sensor_msgs/msg/LaserScan"](
                header=header(i, frame_id),
                time_increment=0.0,
                scan_time=0.0,
                intensities=np.zeros(0, np.float32),
                **values,
            )
            bag.write(scan_conn, (10 + i) * 10**9, ts.serialize_ros1(msg, "sensor_msgs/msg/LaserScan"))
            qx, qy, qz, qw = (quaternions or [(0.0, 0.0, 0.0, 1.0)] * len(scans))[i]
            zero = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
            odom = t["nav_msgs/msg/Odometry"](
                header=header(i + odom_offset_s),
                child_frame_id=(odom_children or ["base"] * len(scans))[i],
                pose=t["geometry_msgs/msg/PoseWithCovariance"](
                    pose=t["geometry_msgs/msg/Pose"](
                        position=t["geometry_msgs/msg/Point"](x=0.1 * i, y=0.0, z=0.0),
                        orientation=t["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
                    ),
                    covariance=np.zeros(36),
                ),
                twist=t["geometry_msgs/msg/TwistWithCovariance"](
                    twist=t["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
                ),
            )
            stamp = (10 + i + odom_offset_s) * 10**9
            bag.write(odom_conn, stamp, ts.serialize_ros1(odom, "nav_msgs/msg/Odometry"))
    return path


def frames(path: Path, **options: object) -> list[Frame]:
    return list(Ros1BagLoader().load(path, **options).frames())


@pytest.mark.parametrize(
    ("args", "found"),
    [
        ((180, -1.0, -1.0 + 179 * STEP, STEP, 0.0, 30.0), None),
        ((180, -1.0, -1.0 + 180 * STEP, STEP, 0.0, 30.0), None),  # angle_max one increment past the last beam
        ((180, 1.0, 1.0 - 179 * STEP, -STEP, 0.0, 30.0), None),  # clockwise
        ((1, 0.3, 0.3, 0.0, 0.0, 30.0), None),
        ((90, -1.0, -1.0 + 179 * STEP, STEP, 0.0, 30.0), "90 ranges, but angle_min -1.0"),
        ((180, -1.0, 1.0, 0.0, 0.0, 30.0), "(angle_increment 0), expected a non-zero angle_increment"),
        ((180, -1.0, 30.0, 10 * STEP, 0.0, 30.0), "span 1790 deg, expected at most a full turn"),
        ((180, math.nan, 1.0, STEP, 0.0, 30.0), "expected finite numbers"),
        ((0, -1.0, 1.0, STEP, 0.0, 30.0), "no ranges, expected at least one beam"),
        ((180, -1.0, -1.0 + 179 * STEP, STEP, 0.0, 0.0), "expected 0 <= range_min < range_max"),
        ((180, -1.0, -1.0 + 179 * STEP, STEP, -1.0, 30.0), "expected 0 <= range_min < range_max"),
    ],
)
def test_laserscan_fields(args: tuple[Any, ...], found: str | None) -> None:
    problem = laserscan_problem(*args)
    assert (problem is None) if found is None else (problem is not None and found in problem)


def test_quaternions() -> None:
    assert quaternion_problem(0.0, 0.0, 0.0, 1.0) is None
    assert "has norm 0, expected a unit quaternion" in str(quaternion_problem(0.0, 0.0, 0.0, 0.0))
    assert "norm nan" in str(quaternion_problem(math.nan, 0.0, 0.0, 1.0))
    assert quaternion_problem(0.0, 0.0, 0.0, 1.5) is not None
    s, c = math.sin(0.6), math.cos(0.6)  # yaw 1.2, scaled by 1.05: normalised before the yaw is taken
    assert yaw_from_quaternion(0.0, 0.0, 1.05 * s, 1.05 * c) == pytest.approx(1.2, abs=1e-12)


def test_a_range_count_that_disagrees_with_the_angles_is_refused(tmp_path: Path) -> None:
    good = write_bag(tmp_path / "good.bag", [{}, {}])
    assert len(frames(good)) == 2
    fencepost = write_bag(tmp_path / "fp.bag", [{"angle_max": -math.pi / 2 + 180 * STEP}] * 2)
    assert len(frames(fencepost)) == 2
    bad = write_bag(tmp_path / "bad.bag", [{}, {"ranges": np.full(90, 2.0, np.float32)}])
    with pytest.raises(ParseError, match=r"bad\.bag\[message #1\]: topic /scan: LaserScan 90 ranges, but .* 180 beams"):
        frames(bad)


def test_a_reading_of_1e30_m_is_one_line_naming_the_message_without_a_numpy_warning(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """range_max = float32's largest value lets any reading through: a 1e30 m reading used to reach the map's
    grid (a numpy cast warning on stderr) and fail there naming a map point, not the message."""
    far = np.full(180, 2.0, np.float32)
    far[4] = 1e30
    big = float(np.finfo(np.float32).max)
    path = write_bag(tmp_path / "far.bag", [{"range_max": big}, {"range_max": big, "ranges": far}])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.simplefilter("ignore", ResourceWarning)  # another test's garbage, freed here by chance
        with pytest.raises(ParseError) as info:
            frames(path)
    assert str(info.value) == (
        f"{path}[message #1]: topic /scan: LaserScan range 5 of 180 is 1e+30 m (range_max 3.40282e+38 m), "
        "expected at most 1e+08 m: no laser measures farther (a reading beyond range_max is no return)"
    )
    assert capfd.readouterr().err == ""
    assert reading_problem(far, 0.0, 30.0) is None  # beyond a real range_max it is no return, as before
    assert reading_problem(np.array([np.nan, np.inf, 1e8]), 0.0, big) is None


def test_a_zero_quaternion_is_refused_not_read_as_yaw_zero(tmp_path: Path) -> None:
    path = write_bag(tmp_path / "q.bag", [{}, {}], [(0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 0.0)])
    with pytest.raises(ParseError, match=r"q\.bag\[message #1\]: topic /odom: orientation quaternion .* has norm 0"):
        frames(path)


def test_an_empty_scan_topic_is_refused_at_load_time(tmp_path: Path) -> None:
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    with Writer(tmp_path / "e.bag") as bag:
        bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
    with pytest.raises(TopicError, match=r"e\.bag: topic /scan \(scans\) has no messages"):
        Ros1BagLoader().load(tmp_path / "e.bag")


def test_dropping_every_scan_is_an_error(tmp_path: Path) -> None:
    path = write_bag(tmp_path / "d.bag", [{}, {}], odom_offset_s=90)  # odometry 90 s after the scans
    with pytest.raises(DataError, match=r"d\.bag: all 2 scans of /scan lie outside the pose time span"):
        frames(path, outside_odometry="drop")


def test_ros2_folder_without_metadata_names_the_missing_file(tmp_path: Path) -> None:
    folder = tmp_path / "run1"
    folder.mkdir()
    (folder / "run1_0.db3").write_bytes(b"SQLite format 3\x00")
    for target in (folder, folder / "run1_0.db3"):
        with pytest.raises(DataError, match=r"run1/metadata\.yaml: missing; .*\(found: run1_0\.db3\)"):
            load(target)


@pytest.mark.parametrize("fmt", ["ros2-mcap", "ros2-sqlite3"])
def test_a_file_read_as_a_ros2_bag_is_named_not_its_folder(tmp_path: Path, fmt: str) -> None:
    """``--from ros2-mcap`` on a ROS1 ``.bag`` used to blame the folder it sits in (``.: not a ROS2 bag folder``)."""
    bag = tmp_path / "pl.bag"
    bag.write_bytes(b"#ROSBAG V2.0\n")  # never read: the path alone is refused
    with pytest.raises(DataError) as info:
        load(bag, fmt)
    assert str(info.value) == (
        f"{bag}: not a ROS2 bag; expected its folder (metadata.yaml beside .db3/.mcap storage files) "
        "or one of its .db3/.mcap storage files"
    )


def test_old_bag_versions_say_what_is_supported() -> None:
    assert version_problem(b"#ROSBAG V2.0") is None
    problem = str(version_problem(b"#ROSRECORD V1.2"))
    assert "ROS1 bag format 1.2 (ROS 0.5 to 1.0" in problem and "expected ROS1 bag format 2.0" in problem
    assert "unknown ROS1 bag version '#ROSBAG V3.0'" in str(version_problem(b"#ROSBAG V3.0"))


def test_damaged_bags_say_what_is_wrong(tmp_path: Path) -> None:
    Ros1BagWriter().write(_sequence(), tmp_path / "ok.bag")
    data = (tmp_path / "ok.bag").read_bytes()
    assert damage(tmp_path / "ok.bag") is None  # a consistent bag walks to its end
    # an index-data record whose length disagrees with its entry count (as in a real 2010 bag)
    start, header_len = next((pos, hl) for pos, hl, op in _records(data) if op == 4)
    (data_len,) = struct.unpack_from("<I", data, start + 4 + header_len)
    bad = bytearray(data)
    struct.pack_into("<I", bad, start + 4 + header_len, data_len + 8)
    (tmp_path / "idx.bag").write_bytes(bytes(bad))
    with pytest.raises(
        ParseError, match=rf"idx\.bag: damaged ROS1 bag: the index data record at byte {start} declares"
    ):
        Ros1BagLoader().load(tmp_path / "idx.bag")
    (tmp_path / "cut.bag").write_bytes(data[: len(data) // 2])
    with pytest.raises(ParseError, match=r"cut\.bag: damaged ROS1 bag: .*(truncated|points its index)"):
        Ros1BagLoader().load(tmp_path / "cut.bag")


def _records(data: bytes) -> list[tuple[int, int, int]]:
    """``(offset, header length, op)`` of the top-level records of a bag 2.0 file."""
    out, pos = [], len(b"#ROSBAG V2.0\n")
    while pos < len(data):
        (header_len,) = struct.unpack_from("<I", data, pos)
        header = data[pos + 4 : pos + 4 + header_len]
        op = header[header.index(b"op=") + 3]
        (data_len,) = struct.unpack_from("<I", data, pos + 4 + header_len)
        out.append((pos, header_len, op))
        pos += 8 + header_len + data_len
    return out


def _sequence(n: int = 4) -> Sequence:
    angles = np.linspace(-1.0, 1.0, 21)
    return Sequence.from_frames(
        "s", [Frame(i, Scan(np.full(21, 3.0), angles, 5.0 + i, 20.0), np.array([0.1 * i, 0.0, 0.0])) for i in range(n)]
    )


def test_the_bag_writer_refuses_what_the_reader_refuses(tmp_path: Path) -> None:
    wide = np.arange(100) * 0.1  # 99 steps of 0.1 rad: more than a full turn
    seq = Sequence.from_frames("w", [Frame(0, Scan(np.ones(100), wide, 1.0, 5.0), np.zeros(3))])
    with pytest.raises(UnwritableError, match=r"w\.bag: scan #0: LaserScan 100 ranges .* expected at most a full turn"):
        Ros1BagWriter().write(seq, tmp_path / "w.bag")
    nan_pose = Sequence.from_frames(
        "p", [Frame(0, Scan(np.ones(3), np.array([0.0, 0.1, 0.2]), 1.0, 5.0), np.array([0.0, math.nan, 0.0]))]
    )
    with pytest.raises(UnwritableError, match=r"p\.bag: scan #0: odom pose \[0\.0, nan, 0\.0\] is not three finite"):
        Ros1BagWriter().write(nan_pose, tmp_path / "p.bag")
    far = Sequence.from_frames(
        "f", [Frame(0, Scan(np.array([1.0, 1e30]), np.array([0.0, 0.1]), 1.0, 1e31), np.zeros(3))]
    )
    with pytest.raises(
        UnwritableError, match=r"f\.bag: scan #0: LaserScan range 2 of 2 is 1e\+30 m .* at most 1e\+08 m"
    ):
        Ros1BagWriter().write(far, tmp_path / "f.bag")
    with pytest.raises(UnwritableError, match=r"e\.bag: the sequence has no scans"):
        Ros1BagWriter().write(Sequence.from_frames("e", []), tmp_path / "e.bag")
    assert list(tmp_path.iterdir()) == []


def test_scans_of_two_lasers_on_one_topic_are_refused_not_placed_with_one_mount(tmp_path: Path) -> None:
    """Two lasers publishing on one topic (a front and a rear scanner both on /scan) used to load as one laser:
    every scan got the mount of the first scan's frame, the rear laser's placed where the front one sits."""
    path = write_bag(tmp_path / "two.bag", [{"frame_id": "front"}, {"frame_id": "/front"}, {"frame_id": "rear"}])
    with pytest.raises(
        ParseError,
        match=r"two\.bag\[message #2\]: topic /scan: scan in frame 'rear', but the topic's first scan is "
        r"in frame 'front'; expected one laser per topic",
    ):
        list(load(path).frames())
    assert (
        len(list(load(write_bag(tmp_path / "one.bag", [{"frame_id": "front"}, {"frame_id": "/front"}])).frames())) == 2
    )


def test_odometry_of_two_publishers_on_one_topic_is_refused_not_interleaved(tmp_path: Path) -> None:
    """Wheel odometry and a filter both publishing on /odom used to be read as one track, jumping between
    the two estimates at every message."""
    path = write_bag(tmp_path / "two.bag", [{}, {}, {}], odom_children=["base", "base", "base_filtered"])
    with pytest.raises(
        ParseError,
        match=r"two\.bag\[message #2\]: topic /odom: pose of 'x' -> 'base_filtered', but the topic's "
        r"first message is 'x' -> 'base'; expected one frame pair per topic",
    ):
        list(load(path).frames())
