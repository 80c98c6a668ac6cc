"""A bag's odometry stamps: sorted when they go back at most 1 s, refused at the first message that goes further.

The pose track is sorted by header stamp, so a message stamped seconds back (a clock jump, a second
publisher) used to be interpolated into the scans beside its stamp without a word.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.errors import ParseError
from albot1.data.loaders.rosbag.loader import Ros1BagLoader, Ros2BagLoader
from albot1.data.loaders.rosbag.msg import seconds_to_ns
from albot1.data.loaders.rosbag.writer import RosMessages
from albot1.data.model import Frame, Scan

ANGLES = np.deg2rad(np.arange(-90.0, 91.0, 10.0))
#: offsets (s) of each odometry stamp from its message's bag time; never within 1e-3 of the 1 s limit
SHIFTS = st.one_of(st.floats(-0.95, 0.0), st.floats(-30.0, -1.05))


def write(path: Path, shifts: list[float]) -> None:
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    msgs = RosMessages(ts, ros1=False)
    with Writer(path, version=9) as bag:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        odom = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        end = 100.0 + len(shifts)
        for k, shift in enumerate(shifts):
            t = 100.0 + k
            data = msgs.odometry(np.array([0.1 * k, 0.0, 0.0]), seconds_to_ns(t + shift), "odom", k)
            bag.write(odom, seconds_to_ns(t), ts.serialize_cdr(data, "nav_msgs/msg/Odometry"))
        data = msgs.odometry(np.zeros(3), seconds_to_ns(end), "odom", 0)  # the track always spans the scan
        bag.write(odom, seconds_to_ns(end), ts.serialize_cdr(data, "nav_msgs/msg/Odometry"))
        f = Frame(0, Scan(np.full(ANGLES.shape, 5.0), ANGLES.copy(), end, 30.0), np.zeros(3))
        bag.write(
            scan, seconds_to_ns(end), ts.serialize_cdr(msgs.scan(f, seconds_to_ns(end)), "sensor_msgs/msg/LaserScan")
        )


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(shifts=st.lists(SHIFTS, min_size=1, max_size=12))
def test_odometry_stamps_are_sorted_within_one_second_and_refused_beyond(shifts: list[float]) -> None:
    stamps = [100.0 + k + s for k, s in enumerate(shifts)]
    latest, first_bad = -np.inf, None
    for k, t in enumerate(stamps):
        if t < latest - 1.0:
            first_bad = k
            break
        latest = max(latest, t)
    with tempfile.TemporaryDirectory() as folder:
        write(Path(folder) / "b", shifts)
        if first_bad is None:
            assert len(list(Ros2BagLoader().load(Path(folder) / "b").frames())) == 1
            return
        with pytest.raises(ParseError) as error:
            list(Ros2BagLoader().load(Path(folder) / "b").frames())
    assert f"b[message #{first_bad}]: topic /odom: pose stamp " in str(error.value)
    assert "expected the topic's stamps in time order (up to 1 s back" in str(error.value)


def write_poses(path: Path, messages: list[tuple[float, float]]) -> None:
    """Odometry messages ``(stamp, x)`` in bag order, each received 1 ms after the previous; a scan at the end."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    msgs = RosMessages(ts, ros1=False)
    end = max(t for t, _ in messages)
    with Writer(path, version=9) as bag:
        scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        odom = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        for k, (t, x) in enumerate(messages):
            data = msgs.odometry(np.array([x, 0.0, 0.0]), seconds_to_ns(t), "odom", k)
            bag.write(odom, seconds_to_ns(100.0 + 0.001 * k), ts.serialize_cdr(data, "nav_msgs/msg/Odometry"))
        f = Frame(0, Scan(np.full(ANGLES.shape, 5.0), ANGLES.copy(), end, 30.0), np.zeros(3))
        ns = seconds_to_ns(end)
        bag.write(scan, ns, ts.serialize_cdr(msgs.scan(f, ns), "sensor_msgs/msg/LaserScan"))


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(
    messages=st.lists(
        st.tuples(st.sampled_from([100.0, 100.25, 100.5, 100.75]), st.sampled_from([0.0, 0.5])), min_size=1, max_size=8
    )
)
def test_one_stamp_holds_one_pose(messages: list[tuple[float, float]]) -> None:
    """Repeated as it was, a message is read once; two poses of one stamp are refused naming a stamp that has two."""
    poses_at: dict[float, set[float]] = {}
    for t, x in messages:
        poses_at.setdefault(t, set()).add(x)
    with tempfile.TemporaryDirectory() as folder:
        write_poses(Path(folder) / "b", messages)
        if all(len(xs) == 1 for xs in poses_at.values()):
            frame = next(iter(Ros2BagLoader().load(Path(folder) / "b").frames()))
            assert frame.odometry[0] == poses_at[max(poses_at)].pop()
            return
        with pytest.raises(ParseError) as error:
            list(Ros2BagLoader().load(Path(folder) / "b").frames())
    text = str(error.value)
    assert "expected one pose per stamp" in text
    stamp = float(text.split("are both stamped ")[1].split(" s")[0])
    assert len(poses_at[stamp]) == 2


@pytest.mark.slow
@settings(max_examples=20, deadline=None)
@given(nodes=st.lists(st.sampled_from(["/diff_drive", "/ekf"]), min_size=1, max_size=8))
def test_ros1_poses_come_from_one_node(nodes: list[str]) -> None:
    """A ROS1 bag records each message's node: Odometry from two nodes is refused at the first of the second."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    from albot1.data.loaders.rosbag.writer import _with_tf

    ts = _with_tf(get_typestore(Stores.ROS1_NOETIC))  # RosMessages builds /tf messages too
    msgs = RosMessages(ts, ros1=True)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "b.bag"
        with Writer(path) as bag:
            conns = {
                n: bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts, callerid=n)
                for n in dict.fromkeys(nodes)
            }
            scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
            for k, node in enumerate(nodes):
                ns = seconds_to_ns(100.0 + k)
                data = msgs.odometry(np.array([0.1 * k, 0.0, 0.0]), ns, "odom", k)
                bag.write(conns[node], ns, ts.serialize_ros1(data, "nav_msgs/msg/Odometry"))
            f = Frame(0, Scan(np.full(ANGLES.shape, 5.0), ANGLES.copy(), 100.0, 30.0), np.zeros(3))
            ns = seconds_to_ns(100.0)
            bag.write(scan, ns, ts.serialize_ros1(msgs.scan(f, ns), "sensor_msgs/msg/LaserScan"))
        other = next((k for k, n in enumerate(nodes) if n != nodes[0]), None)
        if other is None:
            assert len(list(Ros1BagLoader().load(path).frames())) == 1
            return
        with pytest.raises(ParseError) as error:
            list(Ros1BagLoader().load(path).frames())
    assert f"b.bag[message #{other}]: topic /odom: pose published by {nodes[other]}, but message #0's by " in str(
        error.value
    )
