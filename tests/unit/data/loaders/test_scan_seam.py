"""360-degree scans whose last beam repeats the first direction (angle_max = angle_min + 2 pi): the loaders
drop that beam and say so once, so no method sees one direction twice; a scanner stopping one step short of
the full turn keeps every beam."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.loaders.beams import seam_repeat
from albot1.data.loaders.carmen.loader import CarmenLoader
from albot1.data.loaders.registry import load
from albot1.data.loaders.rosbag.msg import scan_arrays
from albot1.data.loaders.rosbag.writer import Ros1BagWriter
from albot1.data.model import Frame, Scan, Sequence
from albot1.data.synthetic.lidar import LaserSpec

QUARTER = math.pi / 2


@pytest.mark.parametrize(
    ("angles", "expected"),
    [
        ([-math.pi, -QUARTER, 0.0, QUARTER, math.pi], True),  # both ends of the turn
        ([0.0, QUARTER, math.pi, 3 * QUARTER, 2 * math.pi], True),  # a driver counting from 0
        ([-math.pi, -QUARTER, 0.0, QUARTER], False),  # one step short: every direction once
        ([-QUARTER, 0.0, QUARTER], False),  # 180 degrees
        ([0.0, 2 * math.pi], False),  # two beams: no spacing to judge by
    ],
)
def test_seam_repeat(angles: list[float], expected: bool) -> None:
    assert seam_repeat(np.array(angles)) is expected


def test_a_laserscan_ending_where_it_starts_loses_its_last_beam() -> None:
    ranges, angles = scan_arrays(
        np.array([1.0, 2.0, 3.0, 4.0, 1.5], np.float32),
        angle_min=-math.pi,
        angle_increment=QUARTER,
        range_min=0.0,
        range_max=10.0,
    )
    assert angles.tolist() == [-math.pi, -QUARTER, 0.0, QUARTER]
    assert ranges.tolist() == [1.0, 2.0, 3.0, 4.0]


def test_a_clockwise_laserscan_ending_where_it_starts_loses_its_last_beam_then_ascends() -> None:
    ranges, angles = scan_arrays(
        np.array([1.0, 2.0, 3.0, 4.0, 1.5], np.float32),
        angle_min=math.pi,
        angle_increment=-QUARTER,
        range_min=0.0,
        range_max=10.0,
    )
    assert angles.tolist() == [-QUARTER, 0.0, QUARTER, math.pi]
    assert ranges.tolist() == [4.0, 3.0, 2.0, 1.0]


def test_a_laserscan_one_step_short_of_the_turn_keeps_every_beam() -> None:
    ranges, angles = scan_arrays(
        np.array([1.0, 2.0, 3.0, 4.0], np.float32),
        angle_min=-math.pi,
        angle_increment=QUARTER,
        range_min=0.0,
        range_max=10.0,
    )
    assert angles.tolist() == [-math.pi, -QUARTER, 0.0, QUARTER]
    assert ranges.tolist() == [1.0, 2.0, 3.0, 4.0]


def _seam_sequence(scans: int = 3) -> Sequence:
    angles = np.array([-math.pi, -QUARTER, 0.0, QUARTER, math.pi])
    frames = [
        Frame(i, Scan(np.array([1.0, 2.0, 3.0, 4.0, 1.0]), angles, 1.0 + i, 10.0), np.array([0.1 * i, 0.0, 0.0]))
        for i in range(scans)
    ]
    return Sequence("seam", lambda: iter(frames), scan_count=scans)


def test_a_bag_of_360_degree_scans_listing_both_ends_loads_each_direction_once(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "seam.bag"
    Ros1BagWriter().write(_seam_sequence(), path)
    with caplog.at_level(logging.WARNING):
        frames = list(load(path))
    # angles as the bag stores them: float32 angle_min and angle_increment
    np.testing.assert_allclose([f.scan.angles for f in frames], [[-math.pi, -QUARTER, 0.0, QUARTER]] * 3, atol=1e-6)
    assert [f.scan.ranges.tolist() for f in frames] == [[1.0, 2.0, 3.0, 4.0]] * 3
    said = [r.getMessage() for r in caplog.records if "points where the first does" in r.getMessage()]
    assert said == [
        f"{path}: topic /scan (message #0): the last of 5 beams points where the first does (the beams span exactly "
        "360 deg); that repeated direction is dropped, leaving 4 beams per scan"
    ]


def test_a_carmen_robotlaser1_spanning_360_degrees_over_n_minus_1_steps_loses_its_last_beam(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    lines = [
        f"ROBOTLASER1 0 {-math.pi!r} {2 * math.pi!r} {QUARTER!r} 10.0 0.01 0 5 1.0 2.0 3.0 4.0 1.0 0 "
        f"0 0 0 0 0 0 0 0 0 0 0 {t} host {t}"
        for t in (1.0, 2.0)
    ]
    path = tmp_path / "seam.clf"
    path.write_text("\n".join(lines) + "\n")
    with caplog.at_level(logging.WARNING):
        frames = list(CarmenLoader().load(path).frames())
    assert [f.scan.angles.tolist() for f in frames] == [[-math.pi, -QUARTER, 0.0, QUARTER]] * 2
    assert [f.scan.ranges.tolist() for f in frames] == [[1.0, 2.0, 3.0, 4.0]] * 2
    said = [r.getMessage() for r in caplog.records if "points where the first does" in r.getMessage()]
    assert said == [
        f"{path}:1: ROBOTLASER1: the last of 5 beams points where the first does (the beams span exactly 360 deg); "
        "that repeated direction is dropped, leaving 4 beams per scan"
    ]


def test_a_simulated_360_degree_scanner_measures_each_direction_once() -> None:
    laser = LaserSpec(beams=4, fov_deg=360.0)
    assert laser.angles.tolist() == [-math.pi, -QUARTER, 0.0, QUARTER]
    assert laser.resolution_deg == 90.0
    assert LaserSpec(beams=181).angles[[0, 90, 180]].tolist() == [-QUARTER, 0.0, QUARTER]
