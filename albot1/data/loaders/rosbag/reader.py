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
import logging
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
    for i, _, msg in published_messages(reader, topic, shown):
        yield i, msg


def published_messages(reader: AnyReader, topic: str, shown: Path) -> Iterator[tuple[int, str | None, Any]]:
    """``(index, publisher, message)`` of one topic in bag order; the publisher is the node a ROS1 bag
    records per connection (``callerid``), None where the bag records none (ROS2 bags)."""
    connections = [c for c in reader.connections if c.topic == topic]
    for i, (conn, _, raw) in _guarded(reader.messages(connections=connections), shown, topic):
        publisher = getattr(conn.ext, "callerid", None)
        yield i, (str(publisher) if publisher else None), _decode(reader, raw, conn.msgtype, shown, topic, i)


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


log = logging.getLogger(__name__)

#: Two poses of one stamp at most this far apart are one estimate published again before its stamp moved on
#: (tf2's TF_REPEATED_DATA: robot_state_publisher, Gazebo's odometry, robot_localization): the first is kept, as
#: tf2 keeps it, and the loader says how many it dropped. Further apart they are two estimates: refused.
SAME_ESTIMATE_M = 0.1
SAME_ESTIMATE_DEG = 5.0


class _PoseStream:
    """One pose topic's (or ``/tf`` link's) messages as they are read; :meth:`track` sorts them by stamp.

    Stamps may go back at most :data:`DEFAULT_TIME_TOLERANCE_S` (they are sorted within it): one message
    stamped seconds back (a clock jump, a second publisher of the same frames on ``/tf``) used to land among
    poses of another time and be interpolated into the scans beside it without a word (a glitch 5.8 s back
    moved a scan 1.1 m and stretched a 3.0 m path to 5.2 m); CARMEN's reader refuses such a step back of its
    ODOM/TRUEPOS lines the same way. In a ROS1 bag, which records each message's node, the poses must come
    from one node (a wheel controller and a filter both publishing ``odom -> base_link``). Two messages of
    one stamp must hold one pose: the track used to take
    the first at that instant and jump to the second right after it, as a trajectory file's two poses of one
    time are refused (:func:`albot1.data.trajectory.refuse_repeated_stamps`); a message repeated as it was
    is read once.
    """

    def __init__(self, shown: Path, topic: str) -> None:
        self.shown, self.topic = shown, topic
        self.latest, self.latest_index = -math.inf, -1
        self.times: list[float] = []
        self.poses: list[tuple[float, float, float]] = []
        self.indexes: list[int] = []
        self.publisher: tuple[str, int] | None = None  # the first message's node and index (ROS1 bags)

    def add(self, t: float, pose: tuple[float, float, float], index: int, publisher: str | None = None) -> None:
        if publisher is not None:
            if self.publisher is None:
                self.publisher = (publisher, index)
            elif publisher != self.publisher[0]:
                raise ParseError(
                    self.shown,
                    f"topic {self.topic}: pose published by {publisher}, but message #{self.publisher[1]}'s by "
                    f"{self.publisher[0]}; expected one publisher of these poses (two nodes' estimates "
                    f"interleaved make one track jump between them)",
                    index=index,
                )
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
        self.times.append(t)
        self.poses.append(pose)
        self.indexes.append(index)

    def track(self) -> PoseTrack:
        """The poses sorted by stamp, the first of each stamp; a ParseError naming both messages of a stamp that
        holds two estimates (poses further apart than :data:`SAME_ESTIMATE_M` / :data:`SAME_ESTIMATE_DEG`)."""
        order = sorted(range(len(self.times)), key=lambda i: (self.times[i], self.indexes[i]))
        kept: list[int] = []
        repeated: list[int] = []  # later poses of a stamp, close to its first: dropped, and said
        for i in order:
            if kept and self.times[kept[-1]] == self.times[i]:
                if self.poses[i] == self.poses[kept[-1]]:
                    continue  # the same message again: read once
                if _same_estimate(self.poses[kept[-1]], self.poses[i]):
                    repeated.append(i)
                    continue
                self._refuse_two_estimates(kept[-1], i)
            kept.append(i)
        if repeated:
            first = repeated[0]
            log.warning(
                "%s: topic %s: %d pose(s) at a stamp already given (first: message #%d at %.9f s), each within "
                "%g m and %g deg of that stamp's first pose; kept the first of each stamp, as tf2 does "
                "(TF_REPEATED_DATA)",
                self.shown, self.topic, len(repeated), self.indexes[first], self.times[first], SAME_ESTIMATE_M,
                SAME_ESTIMATE_DEG,
            )  # fmt: skip
        return PoseTrack.build([self.times[i] for i in kept], [self.poses[i] for i in kept])

    def _refuse_two_estimates(self, a: int, b: int) -> None:
        """A ParseError naming the two messages whose poses of one stamp are two estimates."""
        where = (
            f"messages #{self.indexes[a]} and #{self.indexes[b]} are"
            if self.indexes[a] != self.indexes[b]
            else f"message #{self.indexes[a]} holds two transforms"
        )
        raise ParseError(
            self.shown,
            f"topic {self.topic}: {where} both stamped {self.times[a]:.9f} s with two poses "
            f"{_shown_pose(self.poses[a])} and {_shown_pose(self.poses[b])}; expected one pose per stamp (poses "
            f"within {SAME_ESTIMATE_M:g} m and {SAME_ESTIMATE_DEG:g} deg are read as one estimate repeated; these "
            f"are two, and which one holds at that time cannot be told)",
            index=self.indexes[b],
        )


def _same_estimate(first: tuple[float, float, float], other: tuple[float, float, float]) -> bool:
    """Whether ``other`` is within :data:`SAME_ESTIMATE_M` and :data:`SAME_ESTIMATE_DEG` of ``first``."""
    turn = math.remainder(other[2] - first[2], math.tau)
    return (
        math.hypot(other[0] - first[0], other[1] - first[1]) <= SAME_ESTIMATE_M
        and abs(math.degrees(turn)) <= SAME_ESTIMATE_DEG
    )


def _shown_pose(pose: tuple[float, float, float]) -> str:
    return "(" + ", ".join(f"{v:.6g}" for v in pose) + ")"


def odometry_track(reader: AnyReader, topic: str, shown: Path) -> PoseTrack:
    """The poses of a ``nav_msgs/Odometry`` topic as a track; all in one ``frame_id -> child_frame_id`` pair.

    Two publishers on one topic (wheel odometry and a filter's both on ``/odom``) would otherwise be
    interleaved into one track that jumps between two estimates at every message.
    """
    stream = _PoseStream(shown, topic)
    frames: tuple[str, str] | None = None
    for i, publisher, msg in published_messages(reader, topic, shown):
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
        stream.add(header_stamp(msg), pose, i, publisher)
    if not stream.times:
        raise DataError(f"{shown}: topic {topic} has no messages, so there is no pose to give the scans")
    return stream.track()


def tf_track(reader: AnyReader, topic: str, odom_frame: str, base_frame: str | None, shown: Path) -> PoseTrack:
    """The ``odom_frame -> base_frame`` transforms of a TFMessage topic as a track.

    Only direct transforms count (no chaining through intermediate frames);
    ``base_frame`` is guessed when ``odom_frame`` has exactly one child.
    """
    by_child: dict[str, _PoseStream] = {}
    pairs: set[tuple[str, str]] = set()
    for i, publisher, msg in published_messages(reader, topic, shown):
        for tf in msg.transforms:
            parent, child = tf.header.frame_id.lstrip("/"), tf.child_frame_id.lstrip("/")
            pairs.add((parent, child))
            if parent != odom_frame or (base_frame is not None and child != base_frame):
                continue
            link = f"{topic} ({parent} -> {child})"
            pose = _planar_pose(shown, link, i, tf.transform.translation, tf.transform.rotation)
            by_child.setdefault(child, _PoseStream(shown, link)).add(header_stamp(tf), pose, i, publisher)
    seen = ", ".join(f"{p} -> {c}" for p, c in sorted(pairs)) or "none"
    if len(by_child) != 1:
        wanted = f"{odom_frame} -> {base_frame}" if base_frame else f"{odom_frame} -> <one child frame>"
        problem = "several children" if len(by_child) > 1 else "no such transform"
        raise TopicError(
            f"{shown}: topic {topic}: expected transforms {wanted} ({problem}); transforms seen: {seen}; "
            f"choose the frames with odom_frame= / base_frame="
        )
    return next(iter(by_child.values())).track()
