"""Reading one bag safely with ``rosbags``: open, stream a topic's messages, pose tracks.

``rosbags`` reports malformed input with its own errors but also with bare
assertions and ``struct``/``KeyError`` failures deep inside its readers;
everything here turns those into :class:`ParseError` naming the file and,
for messages, the topic and the message index, so no library traceback
reaches a user. ``rosbags`` is imported lazily (this module is reached from
the CLI).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from albot1.data.errors import DataError, ParseError, TopicError
from albot1.data.loaders.base import DEFAULT_TIME_TOLERANCE_S
from albot1.data.loaders.rosbag.bag1_check import describe_failure
from albot1.data.loaders.rosbag.msg import PoseTrack, quaternion_problem, stamp_seconds, yaw_from_quaternion

if TYPE_CHECKING:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys.store import Typestore


@functools.cache
def _ros2_default_typestore() -> Typestore:
    """Types for ROS2 bags recorded without embedded message definitions."""
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE)


def _reason(exc: BaseException) -> str:
    """A one-line reason, even for ``rosbags``' bare assertions (named by the failing function)."""
    text = " ".join(str(exc).split())
    if text:
        return text if type(exc).__name__ == "AnyReaderError" else f"{type(exc).__name__}: {text}"
    tb = exc.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    where = f" in rosbags' {tb.tb_frame.f_code.co_qualname}" if tb is not None else ""
    return f"{type(exc).__name__}{where}"


@contextmanager
def opened_bag(bag: Path, shown: Path) -> Iterator[AnyReader]:
    """An open AnyReader; any failure to open becomes one ParseError naming ``shown``.

    ``rosbags`` signals malformed bags with its own errors but also with bare
    ``AssertionError``/``struct.error``/``KeyError`` from deep inside its
    index readers, so everything raised while *opening* is translated here.
    """
    from rosbags.highlevel import AnyReader

    try:
        reader = AnyReader([bag], default_typestore=_ros2_default_typestore())
        reader.open()
    except Exception as exc:  # noqa: BLE001 - see docstring: rosbags fails in many ways on bad files
        if bag.is_file():  # a ROS1 bag: say what is wrong with the file rather than where rosbags stopped
            raise ParseError(shown, describe_failure(bag, _reason(exc))) from exc
        raise ParseError(shown, f"rosbags cannot open this bag: {_reason(exc)}") from exc
    try:
        yield reader
    finally:
        reader.close()


def _guarded(messages: Iterator[Any], shown: Path, topic: str) -> Iterator[tuple[int, Any]]:
    """``(message index within the topic, item)``; a read failure names the index."""
    i = 0
    while True:
        try:
            item = next(messages)
        except StopIteration:
            return
        except Exception as exc:  # noqa: BLE001 - corrupt chunks fail in rosbags with arbitrary errors
            raise ParseError(shown, f"topic {topic}: cannot read the message: {_reason(exc)}", index=i) from exc
        yield i, item
        i += 1


def _decode(reader: AnyReader, raw: bytes, msgtype: str, shown: Path, topic: str, index: int) -> Any:
    try:
        return reader.deserialize(raw, msgtype)
    except Exception as exc:  # noqa: BLE001 - truncated or mistyped payloads raise assorted errors
        raise ParseError(
            shown, f"topic {topic}: cannot decode a {msgtype} message: {_reason(exc)}", index=index
        ) from exc


def topic_messages(reader: AnyReader, topic: str, shown: Path) -> Iterator[tuple[int, Any]]:
    """Decoded messages of one topic in bag order, with their index in the topic."""
    connections = [c for c in reader.connections if c.topic == topic]
    for i, (conn, _, raw) in _guarded(reader.messages(connections=connections), shown, topic):
        yield i, _decode(reader, raw, conn.msgtype, shown, topic, i)


def header_stamp(msg: Any) -> float:
    return stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)


def _planar_pose(shown: Path, topic: str, index: int, p: Any, q: Any) -> tuple[float, float, float]:
    """``(x, y, yaw)`` of a position and orientation; a ParseError for a non-finite position or a bad quaternion."""
    x, y = float(p.x), float(p.y)
    if not (math.isfinite(x) and math.isfinite(y)):
        raise ParseError(shown, f"topic {topic}: position ({x!r}, {y!r}), expected finite numbers", index=index)
    quaternion = (float(q.x), float(q.y), float(q.z), float(q.w))
    problem = quaternion_problem(*quaternion)
    if problem is not None:
        raise ParseError(shown, f"topic {topic}: {problem}", index=index)
    return x, y, yaw_from_quaternion(*quaternion)


class _StampOrder:
    """A pose topic's header stamps may go back at most :data:`DEFAULT_TIME_TOLERANCE_S` (they are sorted within it).

    The track is sorted by stamp, so one message stamped seconds back (a clock jump, a second publisher of the
    same frames on ``/tf``) used to land among poses of another time and be interpolated into the scans beside
    it without a word (a glitch 5.8 s back moved a scan 1.1 m and stretched a 3.0 m path to 5.2 m); CARMEN's
    reader refuses such a step back of its ODOM/TRUEPOS lines the same way.
    """

    def __init__(self, shown: Path, topic: str) -> None:
        self.shown, self.topic = shown, topic
        self.latest, self.latest_index = -math.inf, -1

    def check(self, t: float, index: int) -> None:
        if t < self.latest - DEFAULT_TIME_TOLERANCE_S:
            raise ParseError(
                self.shown,
                f"topic {self.topic}: pose stamp {t:.9f} s is {self.latest - t:.3f} s before message "
                f"#{self.latest_index}'s {self.latest:.9f} s; expected the topic's stamps in time order (up to "
                f"{DEFAULT_TIME_TOLERANCE_S:g} s back: a clock jump or a second publisher's poses would be "
                f"interpolated into the scans beside them)",
                index=index,
            )
        if t > self.latest:
            self.latest, self.latest_index = t, index


def odometry_track(reader: AnyReader, topic: str, shown: Path) -> PoseTrack:
    """The poses of a ``nav_msgs/Odometry`` topic as a track; all in one ``frame_id -> child_frame_id`` pair.

    Two publishers on one topic (wheel odometry and a filter's both on ``/odom``) would otherwise be
    interleaved into one track that jumps between two estimates at every message.
    """
    times, poses = [], []
    frames: tuple[str, str] | None = None
    order = _StampOrder(shown, topic)
    for i, msg in topic_messages(reader, topic, shown):
        pair = (str(msg.header.frame_id).lstrip("/"), str(msg.child_frame_id).lstrip("/"))
        if frames is None:
            frames = pair
        elif pair != frames:
            raise ParseError(
                shown,
                f"topic {topic}: pose of {pair[0]!r} -> {pair[1]!r}, but the topic's first message is "
                f"{frames[0]!r} -> {frames[1]!r}; expected one frame pair per topic (two publishers' poses "
                f"interleaved would make one track jump between them)",
                index=i,
            )
        pose = _planar_pose(shown, topic, i, msg.pose.pose.position, msg.pose.pose.orientation)
        order.check(header_stamp(msg), i)
        times.append(header_stamp(msg))
        poses.append(pose)
    if not times:
        raise DataError(f"{shown}: topic {topic} has no messages, so there is no pose to give the scans")
    return PoseTrack.build(times, poses)


def tf_track(reader: AnyReader, topic: str, odom_frame: str, base_frame: str | None, shown: Path) -> PoseTrack:
    """The ``odom_frame -> base_frame`` transforms of a TFMessage topic as a track.

    Only direct transforms count (no chaining through intermediate frames);
    ``base_frame`` is guessed when ``odom_frame`` has exactly one child.
    """
    by_child: dict[str, tuple[list[float], list[tuple[float, float, float]]]] = {}
    pairs: set[tuple[str, str]] = set()
    orders: dict[str, _StampOrder] = {}
    for i, msg in topic_messages(reader, topic, shown):
        for tf in msg.transforms:
            parent, child = tf.header.frame_id.lstrip("/"), tf.child_frame_id.lstrip("/")
            pairs.add((parent, child))
            if parent != odom_frame or (base_frame is not None and child != base_frame):
                continue
            pose = _planar_pose(
                shown, f"{topic} ({parent} -> {child})", i, tf.transform.translation, tf.transform.rotation
            )
            times, poses = by_child.setdefault(child, ([], []))
            orders.setdefault(child, _StampOrder(shown, f"{topic} ({parent} -> {child})")).check(header_stamp(tf), i)
            times.append(header_stamp(tf))
            poses.append(pose)
    seen = ", ".join(f"{p} -> {c}" for p, c in sorted(pairs)) or "none"
    if len(by_child) != 1:
        wanted = f"{odom_frame} -> {base_frame}" if base_frame else f"{odom_frame} -> <one child frame>"
        problem = "several children" if len(by_child) > 1 else "no such transform"
        raise TopicError(
            f"{shown}: topic {topic}: expected transforms {wanted} ({problem}); transforms seen: {seen}; "
            f"choose the frames with odom_frame= / base_frame="
        )
    times, poses = next(iter(by_child.values()))
    return PoseTrack.build(times, poses)
