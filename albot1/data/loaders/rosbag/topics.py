"""Which bag topics hold the scans, the odometry and the reference poses.

Guessing is allowed only when it cannot be wrong (exactly one candidate
topic of the required type); otherwise the user names the topic and every
error lists the bag's topics with their types, so the fix is one copy-paste
away. Pure logic over a ``topic -> (type, count)`` table: no ``rosbags``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from albot1.data.errors import TopicError

LASER_SCAN = "sensor_msgs/msg/LaserScan"
MULTI_ECHO_LASER_SCAN = "sensor_msgs/msg/MultiEchoLaserScan"
ODOMETRY = "nav_msgs/msg/Odometry"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
#: The reference topic ``albot1 convert`` writes; an Odometry topic of this
#: name is taken as the reference unless another is named, so converted bags
#: load back without options.
WRITTEN_REFERENCE = "/ground_truth"


def normalize_type(msgtype: str) -> str:
    """ROS1 spells ``sensor_msgs/LaserScan``, ROS2 ``sensor_msgs/msg/LaserScan``: use the latter."""
    parts = msgtype.split("/")
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return msgtype


@dataclass(frozen=True)
class TopicInfo:
    msgtype: str
    count: int


@dataclass(frozen=True)
class TopicChoice:
    """The chosen topics; ``odom_is_tf`` when odometry comes from /tf transforms."""

    scan: str
    odom: str
    odom_is_tf: bool
    reference: str | None


def describe(topics: Mapping[str, TopicInfo]) -> str:
    """``/scan (sensor_msgs/msg/LaserScan, 7374 msgs), ...`` or ``(none)``."""
    if not topics:
        return "(the bag has no topics)"
    return ", ".join(f"{name} ({info.msgtype}, {info.count} msgs)" for name, info in sorted(topics.items()))


def _error(path: Path, problem: str, topics: Mapping[str, TopicInfo]) -> TopicError:
    return TopicError(f"{path}: {problem}; the bag's topics: {describe(topics)}")


def _multi_echo_note(topics: Mapping[str, TopicInfo]) -> str:
    """What to say of ``MultiEchoLaserScan`` topics (several ranges per beam), which are not read."""
    echoes = sorted(name for name, info in topics.items() if info.msgtype == MULTI_ECHO_LASER_SCAN)
    if not echoes:
        return ""
    return (
        f" ({', '.join(echoes)} {'is' if len(echoes) == 1 else 'are'} {MULTI_ECHO_LASER_SCAN}, several echoes per "
        f"beam, which is not read: expected a LaserScan topic, such as the single-echo scan a multi-echo driver "
        f"can publish beside it)"
    )


def _named(path: Path, topics: Mapping[str, TopicInfo], name: str, allowed: tuple[str, ...], option: str) -> str:
    if name not in topics:
        raise _error(path, f"topic {name!r} ({option}) is not in the bag", topics)
    if topics[name].msgtype not in allowed:
        note = _multi_echo_note({name: topics[name]}) if LASER_SCAN in allowed else ""
        raise _error(
            path,
            f"topic {name!r} ({option}) has type {topics[name].msgtype}, expected {' or '.join(allowed)}{note}",
            topics,
        )
    return name


def _single(
    path: Path, topics: Mapping[str, TopicInfo], msgtype: str, option: str, exclude: tuple[str | None, ...] = ()
) -> str | None:
    candidates = sorted(n for n, i in topics.items() if i.msgtype == msgtype and n not in exclude)
    if len(candidates) > 1:
        raise _error(path, f"several {msgtype} topics ({', '.join(candidates)}); choose one with {option}", topics)
    return candidates[0] if candidates else None


def choose_topics(
    path: Path,
    topics: Mapping[str, TopicInfo],
    scan_topic: str | None = None,
    odom_topic: str | None = None,
    reference_topic: str | None = None,
) -> TopicChoice:
    """The scan, odometry and reference topics, or a TopicError listing ``topics``.

    Odometry: the named topic (Odometry or TFMessage), else the only Odometry
    topic other than the reference topic, else ``/tf`` if present. The
    reference topic is the named one, else ``/ground_truth`` if it is an
    Odometry topic (the layout this suite writes), else none.
    """
    if scan_topic is not None:
        scan = _named(path, topics, scan_topic, (LASER_SCAN,), "scan_topic / --scan-topic")
    else:
        guessed = _single(path, topics, LASER_SCAN, "scan_topic / --scan-topic")
        if guessed is None:
            raise _error(path, f"no {LASER_SCAN} topic{_multi_echo_note(topics)}", topics)
        scan = guessed

    reference = None
    if reference_topic is not None:
        reference = _named(path, topics, reference_topic, (ODOMETRY,), "reference_topic / --reference-topic")
    elif odom_topic != WRITTEN_REFERENCE and topics.get(WRITTEN_REFERENCE, TopicInfo("", 0)).msgtype == ODOMETRY:
        reference = WRITTEN_REFERENCE

    if odom_topic is not None:
        odom = _named(path, topics, odom_topic, (ODOMETRY, TF_MESSAGE), "odom_topic / --odom-topic")
    else:
        guessed = _single(path, topics, ODOMETRY, "odom_topic / --odom-topic", exclude=(reference,))
        if guessed is None:
            guessed = "/tf" if topics.get("/tf", TopicInfo("", 0)).msgtype == TF_MESSAGE else None
        if guessed is None:
            raise _error(path, f"no {ODOMETRY} topic and no /tf ({TF_MESSAGE}) to take odometry from", topics)
        odom = guessed
    if odom == reference:
        raise _error(path, f"the odometry and reference topics are both {odom!r}", topics)
    return TopicChoice(scan=scan, odom=odom, odom_is_tf=topics[odom].msgtype == TF_MESSAGE, reference=reference)
