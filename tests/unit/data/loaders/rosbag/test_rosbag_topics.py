"""Topic choice: guess only when exactly one candidate, else a TopicError listing the topics."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.data.errors import TopicError
from albot1.data.loaders.rosbag.topics import (
    LASER_SCAN,
    ODOMETRY,
    TF_MESSAGE,
    TopicInfo,
    choose_topics,
    normalize_type,
)

BAG = Path("run.bag")


def table(**topics: str) -> dict[str, TopicInfo]:
    return {"/" + name: TopicInfo(msgtype, 10) for name, msgtype in topics.items()}


def test_unambiguous_topics_are_guessed() -> None:
    choice = choose_topics(BAG, table(scan=LASER_SCAN, odom=ODOMETRY, tf=TF_MESSAGE))
    assert (choice.scan, choice.odom, choice.odom_is_tf, choice.reference) == ("/scan", "/odom", False, None)


def test_tf_is_used_when_there_is_no_odometry_topic() -> None:
    choice = choose_topics(BAG, table(scan=LASER_SCAN, tf=TF_MESSAGE))
    assert choice.odom == "/tf" and choice.odom_is_tf


def test_ground_truth_topic_written_by_the_converter_is_the_reference() -> None:
    choice = choose_topics(BAG, table(scan=LASER_SCAN, odom=ODOMETRY, ground_truth=ODOMETRY))
    assert (choice.odom, choice.reference) == ("/odom", "/ground_truth")


def test_two_scan_topics_need_a_choice_and_the_error_lists_every_topic() -> None:
    topics = table(base_scan=LASER_SCAN, front_scan=LASER_SCAN, odom_raw=ODOMETRY)
    with pytest.raises(TopicError) as info:
        choose_topics(BAG, topics)
    message = str(info.value)
    assert "run.bag" in message and "scan_topic" in message
    for name in ("/base_scan (sensor_msgs/msg/LaserScan, 10 msgs)", "/front_scan", "/odom_raw (nav_msgs/msg/Odometry"):
        assert name in message
    assert choose_topics(BAG, topics, scan_topic="/base_scan").odom == "/odom_raw"


def test_two_odometry_topics_are_ambiguous_until_one_is_the_reference() -> None:
    topics = table(scan=LASER_SCAN, odom_raw=ODOMETRY, truth=ODOMETRY)
    with pytest.raises(TopicError, match="several nav_msgs/msg/Odometry topics"):
        choose_topics(BAG, topics)
    choice = choose_topics(BAG, topics, reference_topic="/truth")
    assert (choice.odom, choice.reference) == ("/odom_raw", "/truth")


@pytest.mark.parametrize(
    ("kwargs", "expected"),
    [
        ({"scan_topic": "/nope"}, "'/nope' (scan_topic / --scan-topic) is not in the bag"),
        ({"scan_topic": "/odom"}, "has type nav_msgs/msg/Odometry, expected sensor_msgs/msg/LaserScan"),
        ({"odom_topic": "/scan"}, "expected nav_msgs/msg/Odometry or tf2_msgs/msg/TFMessage"),
        ({"reference_topic": "/odom", "odom_topic": "/odom"}, "both '/odom'"),
    ],
)
def test_named_topics_are_checked(kwargs: dict[str, str], expected: str) -> None:
    with pytest.raises(TopicError, match="the bag's topics: /odom") as info:
        choose_topics(BAG, table(scan=LASER_SCAN, odom=ODOMETRY), **kwargs)
    assert expected in str(info.value)


def test_missing_scan_or_odometry() -> None:
    with pytest.raises(TopicError, match="no sensor_msgs/msg/LaserScan topic"):
        choose_topics(BAG, table(odom=ODOMETRY))
    with pytest.raises(TopicError, match="no nav_msgs/msg/Odometry topic and no /tf"):
        choose_topics(BAG, table(scan=LASER_SCAN))
    with pytest.raises(TopicError, match=r"\(the bag has no topics\)"):
        choose_topics(BAG, {})


def test_ros1_type_names_are_normalised() -> None:
    assert normalize_type("sensor_msgs/LaserScan") == LASER_SCAN
    assert normalize_type(ODOMETRY) == ODOMETRY


def test_a_multi_echo_scan_topic_is_named_as_not_read_whether_guessed_or_chosen() -> None:
    """sensor_msgs/MultiEchoLaserScan (several ranges per beam) is refused saying what it is, not only 'no
    LaserScan topic'."""
    topics = table(echoes="sensor_msgs/msg/MultiEchoLaserScan", odom=ODOMETRY)
    with pytest.raises(TopicError, match=r"no sensor_msgs/msg/LaserScan topic \(/echoes is .*MultiEchoLaserScan, "):
        choose_topics(BAG, topics)
    with pytest.raises(TopicError, match=r"has type .*MultiEchoLaserScan, expected .*\(/echoes is .*not read"):
        choose_topics(BAG, topics, scan_topic="/echoes")
