"""Bags written with rosbags and read back by the loaders, on small synthetic sequences."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from albot1.data.errors import DataError, ParseError, TopicError
from albot1.data.loaders.rosbag.loader import Ros1BagLoader, Ros2BagLoader
from albot1.data.loaders.rosbag.msg import ns_text, seconds_to_ns
from albot1.data.loaders.rosbag.writer import Ros1BagWriter, Ros2McapWriter, Ros2Sqlite3Writer, RosMessages
from albot1.data.model import Frame, Scan, Sequence
from albot1.geometry import se2

ANGLES = np.deg2rad(np.arange(-90.0, 90.0, 1.0))
WRITERS = {
    "ros1": (Ros1BagWriter, Ros1BagLoader, "seq.bag"),
    "ros2-sqlite3": (Ros2Sqlite3Writer, Ros2BagLoader, "seq_db3"),
    "ros2-mcap": (Ros2McapWriter, Ros2BagLoader, "seq_mcap"),
}


def synthetic(n: int = 40, reference: bool = True, seed: int = 0) -> Sequence:
    rng = np.random.default_rng(seed)
    frames = []
    for i in range(n):
        ranges = np.round(rng.uniform(0.2, 30.0, ANGLES.shape[0]), 3)
        ranges[rng.random(ANGLES.shape[0]) < 0.1] = np.nan
        ranges[5] = 30.0  # exactly max range is a return, not "no return"
        odom = np.array([0.1 * i, -0.05 * i, se2.wrap(2.9 + 0.05 * i)])
        ref = np.array([1.0 + 0.1 * i, 2.0, 0.01 * i]) if reference else None
        frames.append(Frame(i, Scan(ranges, ANGLES.copy(), 100.0 + 0.2 * i + 1e-6 * i, 30.0), odom, ref))
    return Sequence.from_frames("synthetic", frames)


def assert_same(original: Sequence, loaded: Sequence) -> None:
    pairs = list(zip(original.frames(), loaded.frames(), strict=True))
    for a, b in pairs:
        assert b.index == a.index
        assert np.array_equal(np.isnan(a.scan.ranges), np.isnan(b.scan.ranges))
        assert np.array_equal(a.scan.ranges.astype(np.float32), b.scan.ranges.astype(np.float32), equal_nan=True)
        assert np.max(np.abs(a.scan.angles - b.scan.angles)) < 1e-6
        assert b.scan.timestamp == pytest.approx(a.scan.timestamp, abs=1e-9)
        assert b.scan.max_range == pytest.approx(a.scan.max_range, rel=1e-6)
        for pa, pb in ((a.odometry, b.odometry), (a.reference, b.reference)):
            if pa is None:
                assert pb is None
                continue
            assert pb is not None
            assert np.max(np.abs(pb[:2] - pa[:2])) <= 1e-9
            assert abs(float(se2.wrap(pb[2] - pa[2]))) <= 1e-9


@pytest.mark.parametrize("fmt", list(WRITERS))
@pytest.mark.parametrize("reference", [True, False])
def test_round_trip(tmp_path: Path, fmt: str, reference: bool) -> None:
    writer, loader, name = WRITERS[fmt]
    seq = synthetic(reference=reference)
    writer().write(seq, tmp_path / name)
    assert loader().sniff(tmp_path / name)
    loaded = loader().load(tmp_path / name)
    assert loaded.metadata.format == fmt
    assert loaded.metadata.extra["reference_topic"] == ("/ground_truth" if reference else None)
    assert_same(seq, loaded)


def test_writer_refuses_to_overwrite_and_irregular_beams(tmp_path: Path) -> None:
    (tmp_path / "x.bag").write_bytes(b"")
    with pytest.raises(DataError, match="exists already"):
        Ros1BagWriter().write(synthetic(3), tmp_path / "x.bag")
    frame = next(synthetic(1).frames())
    angles = frame.scan.angles.copy()
    angles[3] += 0.01
    bad = Sequence.from_frames("bad", [Frame(0, Scan(frame.scan.ranges, angles, 1.0, 30.0), frame.odometry)])
    with pytest.raises(DataError, match="scan #0: beam angles are not evenly spaced"):
        Ros2McapWriter().write(bad, tmp_path / "bad")
    assert not (tmp_path / "bad").exists()  # a failed write leaves nothing behind


@pytest.mark.parametrize("times", [[1.0, 2.0, 2.0], [1.0, 2.0, 1.5]])
def test_writer_refuses_scan_stamps_that_do_not_increase(tmp_path: Path, times: list[float]) -> None:
    base = list(synthetic(3, reference=False).frames())
    frames = [
        Frame(i, Scan(f.scan.ranges, f.scan.angles, t, 30.0), f.odometry) for i, (f, t) in enumerate(zip(base, times))
    ]
    with pytest.raises(DataError, match=r"scan #2: timestamp .* is not after the previous scan's .* --retime"):
        Ros1BagWriter().write(Sequence.from_frames("jitter", frames), tmp_path / "j.bag")
    assert not (tmp_path / "j.bag").exists()


@pytest.mark.parametrize(
    ("times", "shown"),
    [
        ([1.0, 1.2, 1.2], ("1.200000000", "1.200000000")),  # 1.2 s used to read 1.2000000000000002
        ([1.0, 1.2, 1.2 + 1e-10], ("1.200000000", "1.200000000")),  # equal on the bag's clock: why it is refused
        ([1700000000.5, 1700000001.25, 1700000000.75], ("1700000000.750000000", "1700000001.250000000")),
    ],
)
def test_the_refused_stamps_are_said_in_nanoseconds_without_float_noise(
    tmp_path: Path, times: list[float], shown: tuple[str, str]
) -> None:
    base = list(synthetic(3, reference=False).frames())
    frames = [
        Frame(i, Scan(f.scan.ranges, f.scan.angles, t, 30.0), f.odometry) for i, (f, t) in enumerate(zip(base, times))
    ]
    with pytest.raises(DataError) as info:
        Ros1BagWriter().write(Sequence.from_frames("jitter", frames), tmp_path / "j.bag")
    assert str(info.value) == (
        f"{tmp_path / 'j.bag'}: scan #2: timestamp {shown[0]} s is not after the previous scan's {shown[1]} s "
        "(stamps on the bag's nanosecond clock); a bag orders scans and matches poses by time, so stamps must "
        "strictly increase (convert with --retime to shift such scans forward)"
    )
    assert ns_text(1_200_000_000) == "1.200000000" and ns_text(0) == "0.000000000"


# --- bags with other layouts, written directly with rosbags -------------------------------------------


def write_ros2(path: Path, build: Callable[[Any, Any, RosMessages], None]) -> None:
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Writer(path, version=9) as bag:
        build(bag, ts, RosMessages(ts, ros1=False))


def scan_frames(n: int) -> list[Frame]:
    return list(synthetic(n, reference=False).frames())


def test_custom_topics_load_with_options_and_error_lists_topics_without(tmp_path: Path) -> None:
    frames = scan_frames(10)

    def build(bag: Any, ts: Any, msgs: RosMessages) -> None:
        scan = bag.add_connection("/base_scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        distractor = bag.add_connection("/front_scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        odom = bag.add_connection("/odom_raw", "nav_msgs/msg/Odometry", typestore=ts)
        for f in frames:
            ns = seconds_to_ns(f.scan.timestamp)
            bag.write(
                odom, ns, ts.serialize_cdr(msgs.odometry(f.odometry, ns, "odom", f.index), "nav_msgs/msg/Odometry")
            )
            for conn in (scan, distractor):
                bag.write(conn, ns, ts.serialize_cdr(msgs.scan(f, ns), "sensor_msgs/msg/LaserScan"))

    write_ros2(tmp_path / "robot", build)
    with pytest.raises(TopicError) as info:
        Ros2BagLoader().load(tmp_path / "robot")
    for expected in (
        "several sensor_msgs/msg/LaserScan topics",
        "/base_scan (sensor_msgs/msg/LaserScan, 10 msgs)",
        "/front_scan (sensor_msgs/msg/LaserScan, 10 msgs)",
        "/odom_raw (nav_msgs/msg/Odometry, 10 msgs)",
    ):
        assert expected in str(info.value)
    loaded = Ros2BagLoader().load(tmp_path / "robot", scan_topic="/base_scan", odom_topic="/odom_raw")
    assert_same(Sequence.from_frames("x", frames), loaded)
    assert loaded.metadata.extra["scan_topic"] == "/base_scan"


def tf_message(ts: Any, msgs: RosMessages, pose: np.ndarray, ns: int, parent: str, child: str) -> Any:
    t = ts.types
    x, y, th = (float(v) for v in pose)
    transform = t["geometry_msgs/msg/TransformStamped"](
        header=msgs.header(ns, parent, 0),
        child_frame_id=child,
        transform=t["geometry_msgs/msg/Transform"](
            translation=t["geometry_msgs/msg/Vector3"](x=x, y=y, z=0.0),
            rotation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(th / 2), w=math.cos(th / 2)),
        ),
    )
    return t["tf2_msgs/msg/TFMessage"](transforms=[transform])


def test_odometry_from_tf_is_interpolated_to_the_scan_stamps(tmp_path: Path) -> None:
    frames = scan_frames(6)
    start, end = np.array([0.0, 0.0, 0.0]), np.array([2.0, 1.0, 0.5])

    def build(bag: Any, ts: Any, msgs: RosMessages) -> None:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        tf = bag.add_connection("/tf", "tf2_msgs/msg/TFMessage", typestore=ts)
        t0, t1 = seconds_to_ns(frames[0].scan.timestamp - 1.0), seconds_to_ns(frames[-1].scan.timestamp + 1.0)
        for ns, pose in ((t0, start), (t1, end)):
            bag.write(
                tf,
                ns,
                ts.serialize_cdr(tf_message(ts, msgs, pose, ns, "odom", "base_footprint"), "tf2_msgs/msg/TFMessage"),
            )
            bag.write(
                tf, ns, ts.serialize_cdr(tf_message(ts, msgs, pose + 5, ns, "map", "odom"), "tf2_msgs/msg/TFMessage")
            )
        for f in frames:
            ns = seconds_to_ns(f.scan.timestamp)
            bag.write(scan, ns, ts.serialize_cdr(msgs.scan(f, ns), "sensor_msgs/msg/LaserScan"))

    write_ros2(tmp_path / "tfbag", build)
    loaded = list(Ros2BagLoader().load(tmp_path / "tfbag").frames())
    t0, t1 = frames[0].scan.timestamp - 1.0, frames[-1].scan.timestamp + 1.0
    for f in loaded:
        fraction = (f.scan.timestamp - t0) / (t1 - t0)
        assert f.odometry == pytest.approx(start + fraction * (end - start), abs=1e-9)
    with pytest.raises(TopicError, match="transforms seen: map -> odom, odom -> base_footprint"):
        list(Ros2BagLoader().load(tmp_path / "tfbag", base_frame="base_link").frames())


def test_scans_outside_the_odometry_span_are_an_error_or_dropped_on_request(tmp_path: Path) -> None:
    frames = scan_frames(8)

    def build(bag: Any, ts: Any, msgs: RosMessages) -> None:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        odom = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        for f in frames:
            ns = seconds_to_ns(f.scan.timestamp)
            bag.write(scan, ns, ts.serialize_cdr(msgs.scan(f, ns), "sensor_msgs/msg/LaserScan"))
            if 2 <= f.index <= 5:
                bag.write(
                    odom, ns, ts.serialize_cdr(msgs.odometry(f.odometry, ns, "odom", f.index), "nav_msgs/msg/Odometry")
                )

    write_ros2(tmp_path / "short_odom", build)
    with pytest.raises(ParseError, match=r"short_odom\[message #0\]: topic /scan: scan stamp .* outside the time span"):
        list(Ros2BagLoader().load(tmp_path / "short_odom").frames())
    kept = list(Ros2BagLoader().load(tmp_path / "short_odom", outside_odometry="drop").frames())
    assert [f.index for f in kept] == [0, 1, 2, 3]
    assert [f.scan.timestamp for f in kept] == pytest.approx([f.scan.timestamp for f in frames[2:6]])
    with pytest.raises(DataError, match="outside_odometry='sometimes'"):
        Ros2BagLoader().load(tmp_path / "short_odom", outside_odometry="sometimes")
    with pytest.raises(DataError, match="unknown bag option"):
        Ros2BagLoader().load(tmp_path / "short_odom", scan_topics="/scan")


def test_a_scan_in_a_long_odometry_gap_is_refused_unless_max_pose_gap_allows_it(tmp_path: Path) -> None:
    """Odometry messages 10 s apart around a scan: its pose used to be interpolated across the gap silently."""
    frames = scan_frames(3)
    odom_at = {0: frames[0].scan.timestamp - 5.0, 2: frames[2].scan.timestamp + 5.0}

    def build(bag: Any, ts: Any, msgs: RosMessages) -> None:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        odom = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        for index, t in odom_at.items():
            ns = seconds_to_ns(t)
            message = msgs.odometry(frames[index].odometry, ns, "odom", index)
            bag.write(odom, ns, ts.serialize_cdr(message, "nav_msgs/msg/Odometry"))
        for f in frames:
            ns = seconds_to_ns(f.scan.timestamp)
            bag.write(scan, ns, ts.serialize_cdr(msgs.scan(f, ns), "sensor_msgs/msg/LaserScan"))

    write_ros2(tmp_path / "gap", build)
    with pytest.raises(ParseError, match=r"gap\[message #0\]: topic /scan: scan at t = .* falls in a 10\.4.. s gap"):
        list(Ros2BagLoader().load(tmp_path / "gap").frames())
    assert len(list(Ros2BagLoader().load(tmp_path / "gap", max_pose_gap=11.0).frames())) == 3
    with pytest.raises(DataError, match=r"max_pose_gap='never'; expected seconds > 0"):
        Ros2BagLoader().load(tmp_path / "gap", max_pose_gap="never")


def test_undecodable_message_and_backwards_stamps_name_the_message_index(tmp_path: Path) -> None:
    frames = scan_frames(4)

    def build(bag: Any, ts: Any, msgs: RosMessages, garbage_at: int | None, order: list[int]) -> None:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        odom = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        for k, i in enumerate(order):
            f = frames[i]
            ns = seconds_to_ns(frames[k].scan.timestamp)  # bag time increases, header stamps follow `order`
            bag.write(
                odom,
                ns,
                ts.serialize_cdr(
                    msgs.odometry(f.odometry, seconds_to_ns(f.scan.timestamp), "odom", 0), "nav_msgs/msg/Odometry"
                ),
            )
            data = (
                b"\x00\x01\x00\x00\x07"
                if k == garbage_at
                else ts.serialize_cdr(msgs.scan(f, seconds_to_ns(f.scan.timestamp)), "sensor_msgs/msg/LaserScan")
            )
            bag.write(scan, ns, data)

    write_ros2(tmp_path / "garbage", lambda b, t, m: build(b, t, m, 2, [0, 1, 2, 3]))
    with pytest.raises(ParseError, match=r"garbage\[message #2\]: topic /scan: cannot decode"):
        list(Ros2BagLoader().load(tmp_path / "garbage").frames())
    write_ros2(tmp_path / "backwards", lambda b, t, m: build(b, t, m, None, [0, 2, 1, 3]))
    with pytest.raises(ParseError, match=r"backwards\[message #2\]: .* earlier than the previous scan"):
        list(Ros2BagLoader().load(tmp_path / "backwards").frames())


def test_streaming_yields_the_first_scan_before_reading_the_rest(tmp_path: Path) -> None:
    Ros1BagWriter().write(synthetic(30), tmp_path / "s.bag")
    frames = Ros1BagLoader().load(tmp_path / "s.bag").frames()
    first = next(frames)
    assert first.index == 0
    frames.close()  # type: ignore[attr-defined]


def test_not_a_bag(tmp_path: Path) -> None:
    (tmp_path / "plain.bag").write_text("FLASER 1 2 3\n")
    assert not Ros1BagLoader().sniff(tmp_path / "plain.bag")
    with pytest.raises(ParseError, match=r"plain.bag:1: the first line is b'FLASER 1 2 3', not a ROS1 bag header"):
        Ros1BagLoader().load(tmp_path / "plain.bag")
    (tmp_path / "trunc.bag").write_bytes(b"#ROSBAG V2.0\n\x04\x00")
    with pytest.raises(ParseError, match=r"trunc.bag: damaged ROS1 bag: the file ends at byte 15 .* \(truncated\)"):
        Ros1BagLoader().load(tmp_path / "trunc.bag")
    with pytest.raises(DataError, match="not a ROS2 bag"):
        Ros2BagLoader().load(tmp_path)


@pytest.mark.parametrize("fmt", list(WRITERS))
def test_a_load_opens_the_bag_once_and_each_pass_over_its_scans_once_more(
    tmp_path: Path, fmt: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Opening a bag parses its index (a ROS2 bag's ``metadata.yaml`` too): most of what loading a small bag costs.

    So the topics and the laser's mount are read in one opening, and a pass reads the pose tracks (first pass
    only) and streams the scans in one more; four openings per load before (docs/benchmarking.md, "Session 23").
    """
    from rosbags.highlevel import AnyReader

    writer, loader, name = WRITERS[fmt]
    seq = synthetic(n=8)
    writer().write(seq, tmp_path / name)
    opened: list[int] = []
    real_open = AnyReader.open

    def counted(self: AnyReader) -> None:
        opened.append(1)
        real_open(self)

    monkeypatch.setattr(AnyReader, "open", counted)
    loaded = loader().load(tmp_path / name)
    assert len(opened) == 1
    assert_same(seq, loaded)  # one pass: the tracks and the scans from one opening
    assert len(opened) == 2
    assert len(list(loaded.frames())) == len(seq)  # a second pass: one more (the tracks were kept)
    assert len(opened) == 3


@pytest.mark.parametrize("back_s", [0.85, 5.7])
def test_a_pose_stamped_seconds_back_is_refused_at_its_message(tmp_path: Path, back_s: float) -> None:
    """Odometry at 10 Hz between scans at 5 Hz; message #41 carries the pose of its time but a stamp ``back_s``
    earlier. Sorted by stamp, a 5.7 s glitch used to be interpolated into the scan beside its stamp without a
    word (a scan moved 1.1 m, the path stretched); now it is refused as CARMEN's reader refuses an ODOM line
    that far back. Within 1 s (transport jitter, the Intel log's 0.9 s) the stamps are still sorted (0.85 s: not
    onto another message's stamp, which would be two poses of one stamp)."""

    def build(bag: Any, ts: Any, msgs: RosMessages) -> None:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        odom = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        for k in range(60):
            t = 10.0 + 0.1 * k + 0.03
            stamp = t - back_s if k == 41 else t
            pose = np.array([0.05 * k, 0.0, 0.0])
            data = msgs.odometry(pose, seconds_to_ns(stamp), "odom", k)
            bag.write(odom, seconds_to_ns(t), ts.serialize_cdr(data, "nav_msgs/msg/Odometry"))
            if k % 2 == 0 and k < 58:
                f = Frame(k // 2, Scan(np.full(ANGLES.shape, 5.0), ANGLES.copy(), 10.1 + 0.1 * k, 30.0), pose)
                bag.write(
                    scan,
                    seconds_to_ns(10.1 + 0.1 * k),
                    ts.serialize_cdr(msgs.scan(f, seconds_to_ns(10.1 + 0.1 * k)), "sensor_msgs/msg/LaserScan"),
                )

    write_ros2(tmp_path / "glitch", build)
    if back_s < 1.0:
        assert len(list(Ros2BagLoader().load(tmp_path / "glitch").frames())) == 29
        return
    with pytest.raises(
        ParseError,
        match=r"glitch\[message #41\]: topic /odom: pose stamp 8\.43.* s is 5\.600 s before message #40's "
        r"14\.03.* s; expected the topic's stamps in time order \(up to 1 s back",
    ):
        list(Ros2BagLoader().load(tmp_path / "glitch").frames())
