"""The laser's mount read from /tf_static (or /tf), written by the bag writers, and its absence reported."""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from albot1.data.errors import DataError
from albot1.data.loaders.rosbag.loader import Ros1BagLoader, Ros2BagLoader
from albot1.data.loaders.rosbag.msg import seconds_to_ns
from albot1.data.loaders.rosbag.writer import Ros1BagWriter, Ros2McapWriter, Ros2Sqlite3Writer, RosMessages
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata

ANGLES = np.deg2rad(np.arange(-90.0, 90.0, 2.0))
OFFSET = (0.25, -0.125, 0.5)


def sequence(n: int = 5, offset: tuple[float, float, float] = OFFSET) -> Sequence:
    frames = [
        Frame(i, Scan(np.full(ANGLES.shape, 2.0 + i), ANGLES.copy(), 10.0 + i, 30.0), np.array([0.5 * i, 0.0, 0.1 * i]))
        for i in range(n)
    ]
    return Sequence.from_frames("mounted", frames, metadata=SequenceMetadata(sensor_offset=offset))


@pytest.mark.parametrize(
    ("writer", "loader", "name"),
    [
        (Ros1BagWriter, Ros1BagLoader, "m.bag"),
        (Ros2Sqlite3Writer, Ros2BagLoader, "m.db3"),
        (Ros2McapWriter, Ros2BagLoader, "m.mcap"),
    ],
)
def test_written_mount_reads_back_as_the_same_offset(
    tmp_path: Path, writer: Any, loader: Any, name: str, caplog: pytest.LogCaptureFixture
) -> None:
    writer().write(sequence(), tmp_path / name)
    with caplog.at_level(logging.WARNING):
        loaded = loader().load(tmp_path / name)
    assert loaded.metadata.sensor_offset == pytest.approx(OFFSET, abs=1e-12)
    assert loaded.metadata.extra["sensor_offset_source"].startswith("/tf_static base_link -> laser: (x, y, yaw) = (")
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]
    got = np.array([f.odometry for f in loaded.frames()])
    assert np.abs(got - np.array([f.odometry for f in sequence().frames()])).max() < 1e-12


def test_converted_bag_carries_tf_static_latched_and_tf_for_odometry(tmp_path: Path) -> None:
    from rosbags.highlevel import AnyReader

    Ros2McapWriter().write(sequence(n=4), tmp_path / "m.mcap")
    Ros1BagWriter().write(sequence(n=4), tmp_path / "m.bag")
    for bag in (tmp_path / "m.mcap", tmp_path / "m.bag"):
        with AnyReader([bag]) as reader:
            counts = {t: i.msgcount for t, i in reader.topics.items()}
            assert counts == {"/scan": 4, "/odom": 4, "/tf": 4, "/tf_static": 1}
            static = next(c for c in reader.connections if c.topic == "/tf_static")
            if bag.suffix == ".bag":
                assert static.ext.latching == 1
            else:
                assert static.ext.offered_qos_profiles[0].durability.name == "TRANSIENT_LOCAL"
            tfs = [
                reader.deserialize(raw, c.msgtype)
                for c, _, raw in reader.messages(connections=[c for c in reader.connections if c.topic == "/tf"])
            ]
        last = tfs[-1].transforms[0]
        assert (last.header.frame_id, last.child_frame_id) == ("odom", "base_link")
        assert (last.transform.translation.x, last.transform.translation.y) == (1.5, 0.0)
        assert 2 * math.atan2(last.transform.rotation.z, last.transform.rotation.w) == pytest.approx(0.3, abs=1e-15)


def test_ros2_outputs_are_named_after_out(tmp_path: Path) -> None:
    Ros2McapWriter().write(sequence(n=2), tmp_path / "intel.mcap")
    Ros2Sqlite3Writer().write(sequence(n=2), tmp_path / "intel.db3")
    Ros2McapWriter().write(sequence(n=2), tmp_path / "run")
    assert sorted(p.name for p in (tmp_path / "intel.mcap").iterdir()) == ["intel.mcap", "metadata.yaml"]
    assert sorted(p.name for p in (tmp_path / "intel.db3").iterdir()) == ["intel.db3", "metadata.yaml"]
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == ["metadata.yaml", "run.mcap"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["intel.db3", "intel.mcap", "run"]  # no staging left
    assert len(list(Ros2BagLoader().load(tmp_path / "intel.mcap").frames())) == 2
    assert len(list(Ros2BagLoader().load(tmp_path / "intel.mcap" / "intel.mcap").frames())) == 2


def test_failed_ros2_write_leaves_nothing(tmp_path: Path) -> None:
    bad = Sequence.from_frames("bad", [Frame(0, Scan(np.ones(3), np.array([0.0, 0.1, 0.3]), 1.0, 30.0), np.zeros(3))])
    with pytest.raises(DataError, match="not evenly spaced"):
        Ros2McapWriter().write(bad, tmp_path / "x.mcap")
    assert list(tmp_path.iterdir()) == []


def _tf(ts: Any, msgs: RosMessages, ns: int, links: list[tuple[str, str, tuple[float, ...], tuple[float, ...]]]) -> Any:
    t = ts.types
    transforms = [
        t["geometry_msgs/msg/TransformStamped"](
            header=msgs.header(ns, parent, 0),
            child_frame_id=child,
            transform=t["geometry_msgs/msg/Transform"](
                translation=t["geometry_msgs/msg/Vector3"](x=xyz[0], y=xyz[1], z=xyz[2]),
                rotation=t["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3]),
            ),
        )
        for parent, child, xyz, q in links
    ]
    return t["tf2_msgs/msg/TFMessage"](transforms=transforms)


def write_bag(
    path: Path,
    topic: str | None,
    links: list[tuple[str, str, tuple[float, ...], tuple[float, ...]]],
    scans: Sequence | None = None,
) -> None:
    """Scans in frame ``laser`` (``scans``, else ``sequence(3)``), odometry of ``base_link``, and ``links`` on
    ``topic`` (None: no tf at all)."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    msgs = RosMessages(ts, ros1=False)
    with Writer(path, version=9) as bag:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        odom = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        tf = bag.add_connection(topic, "tf2_msgs/msg/TFMessage", typestore=ts) if topic else None
        for f in (sequence(3) if scans is None else scans).frames():
            ns = seconds_to_ns(f.scan.timestamp)
            if tf is not None:
                bag.write(tf, ns, ts.serialize_cdr(_tf(ts, msgs, ns, links), "tf2_msgs/msg/TFMessage"))
            bag.write(
                odom, ns, ts.serialize_cdr(msgs.odometry(f.odometry, ns, "odom", f.index), "nav_msgs/msg/Odometry")
            )
            bag.write(scan, ns, ts.serialize_cdr(msgs.scan(f, ns), "sensor_msgs/msg/LaserScan"))


def yaw_q(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def test_bag_without_tf_says_the_mount_is_missing(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    write_bag(tmp_path / "bare", None, [])
    with caplog.at_level(logging.WARNING):
        loaded = Ros2BagLoader().load(tmp_path / "bare")
    note = loaded.metadata.extra["sensor_offset_source"]
    assert note == (
        "no transform base_link -> 'laser' (the scans' frame) in the bag (it has no /tf_static or /tf topic); "
        "the laser is taken to sit at the base's origin (sensor_offset 0)"
    )
    assert loaded.metadata.sensor_offset == (0.0, 0.0, 0.0)
    assert [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING] == [f"{tmp_path / 'bare'}: {note}"]


def test_chained_mount_on_tf_composes_to_the_base(tmp_path: Path) -> None:
    """base_link -> mount (0.5, 0, yaw 90 deg) -> laser (0.2, 0, yaw 90 deg), on /tf beside odom -> base_link."""
    links = [
        ("odom", "base_link", (9.0, 9.0, 0.0), yaw_q(1.0)),
        ("base_link", "mount", (0.5, 0.0, 0.3), yaw_q(math.pi / 2)),
        ("mount", "laser", (0.2, 0.0, 0.1), yaw_q(math.pi / 2)),
    ]
    write_bag(tmp_path / "chain", "/tf", links)
    loaded = Ros2BagLoader().load(tmp_path / "chain")
    assert loaded.metadata.sensor_offset == pytest.approx((0.5, 0.2, math.pi), abs=1e-12)
    assert loaded.metadata.extra["sensor_offset_source"].startswith("/tf base_link -> laser:")


def test_small_tilt_is_projected_and_a_laser_looking_down_refused(tmp_path: Path) -> None:
    tilt = math.radians(2.0)  # 2 deg roll: projected onto the plane
    write_bag(
        tmp_path / "tilted",
        "/tf_static",
        [("base_link", "laser", (0.1, 0.0, 0.2), (math.sin(tilt / 2), 0, 0, math.cos(tilt / 2)))],
    )
    assert Ros2BagLoader().load(tmp_path / "tilted").metadata.sensor_offset == pytest.approx((0.1, 0.0, 0.0), abs=1e-12)
    pitch = math.radians(30.0)  # looking at the floor: neither level nor upside down
    write_bag(
        tmp_path / "down",
        "/tf_static",
        [("base_link", "laser", (0.1, 0.0, 0.2), (0, math.sin(pitch / 2), 0, math.cos(pitch / 2)))],
    )
    with pytest.raises(DataError, match=r"the laser frame 'laser' is tilted 30.0 deg from the base frame 'base_link'"):
        Ros2BagLoader().load(tmp_path / "down")


def distinct_ranges(n: int = 2) -> Sequence:
    """Scans whose every beam has its own range (1 m + 1 cm per beam), so a mirrored beam order shows."""
    ranges = 1.0 + 0.01 * np.arange(ANGLES.size)
    frames = [
        Frame(i, Scan(ranges.copy(), ANGLES.copy(), 10.0 + i, 30.0), np.array([0.5 * i, 0.0, 0.0])) for i in range(n)
    ]
    return Sequence.from_frames("distinct", frames)


@pytest.mark.parametrize(
    ("quaternion", "yaw"),
    [
        ((1.0, 0.0, 0.0, 0.0), 0.0),  # rolled by pi: facing forwards, its y axis to the robot's right
        ((0.0, 1.0, 0.0, 0.0), math.pi),  # pitched by pi: facing backwards, upside down
        ((math.cos(0.25), math.sin(0.25), 0.0, 0.0), 0.5),  # yawed 0.5 rad, then rolled by pi
    ],
)
def test_upside_down_laser_is_read_with_mirrored_beams(
    tmp_path: Path, quaternion: tuple[float, float, float, float], yaw: float
) -> None:
    # A laser rolled (or pitched) by pi scans the base's plane with its y axis pointing right: a beam at
    # angle a of its scan lies at -a on the plane. Such a mount used to be refused as "tilted 180.0 deg".
    write_bag(
        tmp_path / "flipped", "/tf_static", [("base_link", "laser", (0.1, 0.0, 0.2), quaternion)], distinct_ranges()
    )
    loaded = Ros2BagLoader().load(tmp_path / "flipped")
    assert loaded.metadata.sensor_offset == pytest.approx((0.1, 0.0, yaw), abs=1e-12)
    assert loaded.metadata.extra["sensor_offset_source"].endswith("mounted upside down: beam angles mirrored (a -> -a)")
    written = ANGLES.astype(np.float32).astype(np.float64)  # the message's float32 angle_min and increment
    for frame in loaded.frames():
        # the beam written at angle a (range 1 m + 1 cm * its index) is read at -a, angles ascending
        np.testing.assert_allclose(frame.scan.angles, -written[::-1], atol=1e-6)
        np.testing.assert_allclose(frame.scan.ranges, (1.0 + 0.01 * np.arange(ANGLES.size))[::-1], atol=1e-6)


def test_static_mount_not_reaching_the_odometry_base_is_missing(tmp_path: Path) -> None:
    write_bag(tmp_path / "other", "/tf_static", [("chassis", "laser", (0.1, 0.0, 0.0), yaw_q(0.0))])
    loaded = Ros2BagLoader().load(tmp_path / "other")
    assert loaded.metadata.sensor_offset == (0.0, 0.0, 0.0)
    assert (
        "no transform base_link -> 'laser' (the scans' frame) in /tf_static;"
        in loaded.metadata.extra["sensor_offset_source"]
    )
    assert Ros2BagLoader().load(tmp_path / "other", base_frame="chassis").metadata.sensor_offset == pytest.approx(
        (0.1, 0.0, 0.0)
    )


def test_scans_in_the_frame_odometry_moves_need_no_mount(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """Odometry from /tf (odom -> base_link) and scans stamped in base_link itself: offset 0, no warning."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    msgs = RosMessages(ts, ros1=False)
    with Writer(tmp_path / "onbase", version=9) as bag:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        tf = bag.add_connection("/tf", "tf2_msgs/msg/TFMessage", typestore=ts)
        for f in sequence(3).frames():
            ns = seconds_to_ns(f.scan.timestamp)
            link = [("odom", "base_link", (float(f.odometry[0]), 0.0, 0.0), yaw_q(float(f.odometry[2])))]
            bag.write(tf, ns, ts.serialize_cdr(_tf(ts, msgs, ns, link), "tf2_msgs/msg/TFMessage"))
            message = msgs.scan(f, ns)
            message.header.frame_id = "base_link"
            bag.write(scan, ns, ts.serialize_cdr(message, "sensor_msgs/msg/LaserScan"))
    with caplog.at_level(logging.WARNING):
        loaded = Ros2BagLoader().load(tmp_path / "onbase")
    assert loaded.metadata.sensor_offset == (0.0, 0.0, 0.0)
    # odometry on /tf names its base (the child of odom), so the scans' frame is known to be it without a tree
    assert loaded.metadata.extra["sensor_offset_source"] == "the scans' frame 'base_link' is the base frame"
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]


def write_tf_odometry_bag(
    path: Path,
    child: str,
    static: list[tuple[str, str, tuple[float, ...], tuple[float, ...]]],
    dynamic: list[tuple[str, str, tuple[float, ...], tuple[float, ...]]] = (),  # type: ignore[assignment]
    *,
    odometry_topic: bool = False,
) -> None:
    """Scans in frame ``laser``; odometry as ``odom -> child`` on /tf (or, with ``odometry_topic``, as
    nav_msgs/Odometry of ``child`` on /odom); ``static`` links on /tf_static, ``dynamic`` ones beside odom on /tf."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    msgs = RosMessages(ts, ros1=False)
    with Writer(path, version=9) as bag:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        tf = bag.add_connection("/tf", "tf2_msgs/msg/TFMessage", typestore=ts)
        tf_static = bag.add_connection("/tf_static", "tf2_msgs/msg/TFMessage", typestore=ts)
        odom = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts) if odometry_topic else None
        bag.write(tf_static, 0, ts.serialize_cdr(_tf(ts, msgs, 0, static), "tf2_msgs/msg/TFMessage"))
        for f in sequence(3).frames():
            ns = seconds_to_ns(f.scan.timestamp)
            moved = [("odom", child, (float(f.odometry[0]), 0.0, 0.0), yaw_q(float(f.odometry[2])))]
            if odom is not None:
                message = msgs.odometry(f.odometry, ns, "odom", f.index)
                message.child_frame_id = child
                bag.write(odom, ns, ts.serialize_cdr(message, "nav_msgs/msg/Odometry"))
                moved = []
            bag.write(tf, ns, ts.serialize_cdr(_tf(ts, msgs, ns, moved + list(dynamic)), "tf2_msgs/msg/TFMessage"))
            bag.write(scan, ns, ts.serialize_cdr(msgs.scan(f, ns), "sensor_msgs/msg/LaserScan"))


def test_odometry_on_tf_whose_base_the_laser_tree_misses_warns_as_odometry_messages_do(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """odom -> base_footprint on /tf, base_link -> laser static and no link between the two bases: the mount
    used to be taken from base_link, the static tree's unrelated root, without a word."""
    mount = [("base_link", "laser", (0.2, 0.0, 0.0), yaw_q(0.0))]
    write_tf_odometry_bag(tmp_path / "tf", "base_footprint", mount)
    write_tf_odometry_bag(tmp_path / "odom", "base_footprint", mount, odometry_topic=True)
    note = (
        "no transform base_footprint -> 'laser' (the scans' frame) in /tf_static or /tf; the laser is taken to sit "
        "at the base's origin (sensor_offset 0)"
    )
    for name in ("tf", "odom"):
        caplog.clear()
        with caplog.at_level(logging.WARNING):
            loaded = Ros2BagLoader().load(tmp_path / name)
        assert loaded.metadata.sensor_offset == (0.0, 0.0, 0.0)
        assert loaded.metadata.extra["sensor_offset_source"] == note
        assert [r.getMessage() for r in caplog.records] == [f"{tmp_path / name}: {note}"]
    assert Ros2BagLoader().load(tmp_path / "tf").metadata.odometry_source.startswith("/tf transforms odom -> ")


def test_a_tree_split_over_tf_and_tf_static_reaches_the_odometry_base(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """base_footprint -> base_link on /tf (older bags), base_link -> laser static: the two are joined."""
    write_tf_odometry_bag(
        tmp_path / "split",
        "base_footprint",
        [("base_link", "laser", (0.2, 0.0, 0.0), yaw_q(0.0))],
        [("base_footprint", "base_link", (0.05, 0.0, 0.1), yaw_q(math.pi / 2))],
    )
    with caplog.at_level(logging.WARNING):
        loaded = Ros2BagLoader().load(tmp_path / "split")
    assert loaded.metadata.sensor_offset == pytest.approx((0.05, 0.2, math.pi / 2), abs=1e-12)
    assert loaded.metadata.extra["sensor_offset_source"].startswith("/tf_static + /tf base_footprint -> laser: (")
    assert caplog.records == []


def test_a_mount_far_off_the_robot_is_refused_when_the_bag_is_opened(tmp_path: Path) -> None:
    """A /tf_static written in millimetres (200 for 0.2 m) used to load, every scan placed 200 m off the robot
    without a word; the laser mount is now held to MAX_MOUNT_M, in one line naming the link it came from."""
    from albot1.data.errors import ParseError
    from albot1.data.open import open_sequence

    write_bag(tmp_path / "mm", "/tf_static", [("base_link", "laser", (200.0, 0.0, 0.1), yaw_q(0.0))])
    with pytest.raises(
        ParseError,
        match=r"mm: laser mount .* puts the laser 200 m from the robot's base; expected at "
        r"most 20 m .*\(from /tf_static base_link -> laser: \(x, y, yaw\) = \(200, 0, 0\)\)",
    ):
        open_sequence(str(tmp_path / "mm"))
    write_bag(tmp_path / "far", "/tf_static", [("base_link", "laser", (19.0, 0.0, 0.1), yaw_q(0.0))])
    assert open_sequence(str(tmp_path / "far")).metadata.sensor_offset == pytest.approx((19.0, 0.0, 0.0))


def test_two_poses_of_one_stamp_on_tf_are_refused(tmp_path: Path) -> None:
    """Two publishers of odom -> base_link (a wheel controller and a filter, a classic misconfiguration) put two
    poses at one stamp; the track used to take one at that instant and jump to the other right after it (a pose
    repeated as it was is read once: tests/property/test_rosbag_pose_order_props.py)."""
    from albot1.data.errors import ParseError

    other = [("odom", "base_link", (5.0, 5.0, 0.0), yaw_q(0.0))]
    write_tf_odometry_bag(tmp_path / "two", "base_link", [("base_link", "laser", (0.1, 0.0, 0.0), yaw_q(0.0))], other)
    with pytest.raises(
        ParseError,
        match=r"two\[message #0\]: topic /tf \(odom -> base_link\): message #0 holds two transforms both stamped "
        r"10\.000000000 s with two poses \(0, 0, 0\) and \(5, 5, 0\); expected one pose per stamp",
    ):
        list(Ros2BagLoader().load(tmp_path / "two").frames())


def test_a_pose_repeated_at_its_stamp_a_little_off_is_one_estimate_the_first_kept_and_said(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """tf2's TF_REPEATED_DATA: a publisher sends odom -> base_link again before its stamp moved on (Gazebo,
    robot_state_publisher, robot_localization), the pose updated by a few centimetres. tf2 keeps the first; the
    reader did too once, then refused the whole bag; now it keeps the first and says how many it dropped."""
    import logging

    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    msgs = RosMessages(ts, ros1=False)
    with Writer(tmp_path / "again", version=9) as bag:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        tf = bag.add_connection("/tf", "tf2_msgs/msg/TFMessage", typestore=ts)
        for f in sequence(3).frames():
            ns = seconds_to_ns(f.scan.timestamp)
            x, theta = float(f.odometry[0]), float(f.odometry[2])
            for dx in (0.0, 0.02):  # the second 2 cm further on, under the same stamp
                moved = [("odom", "base_link", (x + dx, 0.0, 0.0), yaw_q(theta))]
                bag.write(tf, ns, ts.serialize_cdr(_tf(ts, msgs, ns, moved), "tf2_msgs/msg/TFMessage"))
            bag.write(scan, ns, ts.serialize_cdr(msgs.scan(f, ns), "sensor_msgs/msg/LaserScan"))
    with caplog.at_level(logging.WARNING, logger="albot1.data.loaders.rosbag.reader"):
        frames = list(Ros2BagLoader().load(tmp_path / "again").frames())
    expected = [float(f.odometry[0]) for f in sequence(3).frames()]
    assert [float(f.odometry[0]) for f in frames] == pytest.approx(expected, abs=1e-12)  # each stamp's first pose
    [said] = [r.getMessage() for r in caplog.records if "TF_REPEATED_DATA" in r.getMessage()]
    assert "topic /tf (odom -> base_link): 3 pose(s) at a stamp already given (first: message #1 at" in said


def write_ros1_publishers(path: Path, publishers: list[str], tf: bool) -> None:
    """A ROS1 bag whose odometry (``odom -> base_link`` on /tf, or /odom) comes from ``publishers`` in turn,
    one connection per node as ROS1 records them, at stamps that never coincide; a scan between each two."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    from albot1.data.loaders.rosbag.writer import _with_tf

    ts = _with_tf(get_typestore(Stores.ROS1_NOETIC))
    msgs = RosMessages(ts, ros1=True)
    kind = "tf2_msgs/msg/TFMessage" if tf else "nav_msgs/msg/Odometry"
    with Writer(path) as bag:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        conns = {p: bag.add_connection("/tf" if tf else "/odom", kind, typestore=ts, callerid=p) for p in publishers}
        for k in range(8):
            ns = seconds_to_ns(10.0 + 0.1 * k)
            x = 0.1 * k + (5.0 if publishers[k % len(publishers)] == "/ekf" else 0.0)
            data = (
                _tf(ts, msgs, ns, [("odom", "base_link", (x, 0.0, 0.0), yaw_q(0.0))])
                if tf
                else msgs.odometry(np.array([x, 0.0, 0.0]), ns, "odom", k)
            )
            bag.write(conns[publishers[k % len(publishers)]], ns, ts.serialize_ros1(data, kind))
            if 0 < k < 7:
                f = Frame(k, Scan(np.full(ANGLES.shape, 2.0), ANGLES.copy(), 10.05 + 0.1 * k, 30.0), np.zeros(3))
                bag.write(
                    scan,
                    ns,
                    ts.serialize_ros1(msgs.scan(f, seconds_to_ns(10.05 + 0.1 * k)), "sensor_msgs/msg/LaserScan"),
                )


@pytest.mark.parametrize("tf", [True, False])
def test_ros1_odometry_from_two_nodes_is_refused(tmp_path: Path, tf: bool) -> None:
    """A wheel controller (/diff_drive) and a filter (/ekf) both publishing the robot's pose, at stamps that never
    coincide: interleaved, the track jumped 5 m at every message. A ROS1 bag records each message's node."""
    from albot1.data.errors import ParseError

    write_ros1_publishers(tmp_path / "two.bag", ["/diff_drive", "/ekf"], tf)
    topic = r"/tf \(odom -> base_link\)" if tf else "/odom"
    with pytest.raises(
        ParseError,
        match=rf"two\.bag\[message #1\]: topic {topic}: pose published by /ekf, but message #0's by /diff_drive; "
        r"expected one publisher of these poses",
    ):
        list(Ros1BagLoader().load(tmp_path / "two.bag").frames())
    write_ros1_publishers(tmp_path / "one.bag", ["/diff_drive"], tf)
    assert len(list(Ros1BagLoader().load(tmp_path / "one.bag").frames())) == 6
