"""ACES (CARMEN) -> ROS1 / ROS2 sqlite3 / ROS2 MCAP / albot log -> back: same ranges and poses."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from albot1.data.convert import convert
from albot1.data.errors import ParseError
from albot1.data.loaders.registry import load
from albot1.data.model import Sequence
from albot1.data.transforms import head
from albot1.geometry import se2

pytestmark = pytest.mark.integration

TARGETS = {"ros1": "aces.bag", "ros2-sqlite3": "aces.db3", "ros2-mcap": "aces.mcap", "albot-log": "aces.albotlog"}


@pytest.fixture(scope="module")
def aces_prefix(data_file: Callable[[str], Path]) -> Sequence:
    return head(load(data_file("radish/aces.clf.bz2")), 500).materialize()


def assert_round_trip(original: Sequence, path: Path, expected_format: str) -> None:
    loaded = load(path)  # sniffed: no format name, no topic options
    assert loaded.metadata.format == expected_format
    count = 0
    for a, b in zip(original.frames(), loaded.frames(), strict=True):
        count += 1
        assert np.array_equal(np.isnan(a.scan.ranges), np.isnan(b.scan.ranges)), f"scan {a.index}: NaN positions"
        assert np.array_equal(a.scan.ranges.astype(np.float32), b.scan.ranges.astype(np.float32), equal_nan=True), (
            f"scan {a.index}: ranges"
        )
        assert np.max(np.abs(a.scan.angles - b.scan.angles)) < 1e-6
        assert abs(a.scan.timestamp - b.scan.timestamp) < 1e-6
        d = b.odometry - a.odometry
        assert np.max(np.abs([d[0], d[1], se2.wrap(d[2])])) <= 1e-6, f"scan {a.index}: odometry"
        assert (a.reference is None) == (b.reference is None)
    assert count == len(original)


@pytest.mark.parametrize("fmt", list(TARGETS))
def test_aces_prefix_round_trips(aces_prefix: Sequence, tmp_path: Path, fmt: str) -> None:
    done = convert(aces_prefix, tmp_path / TARGETS[fmt])
    assert (done.format_name, done.scans) == (fmt, 500)
    assert_round_trip(aces_prefix, tmp_path / TARGETS[fmt], fmt)


@pytest.mark.slow
@pytest.mark.whole_log
def test_full_aces_round_trips_through_every_format(data_file: Callable[[str], Path], tmp_path: Path) -> None:
    aces = load(data_file("radish/aces.clf.bz2")).materialize()
    assert len(aces) == 7374
    for fmt, name in TARGETS.items():
        assert convert(aces, tmp_path / name).scans == 7374
        assert_round_trip(aces, tmp_path / name, fmt)


@pytest.mark.parametrize(
    ("name", "reason"),
    [
        ("old-rosbag-laser_scan_matcher-demo.bag", "damaged ROS1 bag: the index data record at byte 792650"),
        ("old-rosbag-laser_scan_sparsifier-demo.bag", "ROS1 bag format 1.2 (ROS 0.5 to 1.0, before 2010)"),
    ],
)
def test_bags_rosbags_cannot_open_give_one_clear_error(
    data_file: Callable[[str], Path], name: str, reason: str
) -> None:
    path = data_file(f"bad-inputs/{name}")
    with pytest.raises(ParseError) as info:
        load(path)
    assert str(info.value).startswith(str(path))
    assert reason in str(info.value)
