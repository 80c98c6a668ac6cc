"""Exact checks of the pure ROS message conversions (no bag, no rosbags)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.loaders.rosbag.msg import (
    PoseTrack,
    quaternion_from_yaw,
    scan_arrays,
    seconds_to_ns,
    split_ns,
    stamp_seconds,
    yaw_from_quaternion,
)


def test_scan_arrays_marks_out_of_range_inf_and_nan_as_no_return() -> None:
    ranges, angles = scan_arrays(
        np.array([0.05, 1.0, np.inf, np.nan, 30.0, 30.5, -np.inf], dtype=np.float32),
        angle_min=-0.5,
        angle_increment=0.25,
        range_min=0.1,
        range_max=30.0,
    )
    assert np.array_equal(np.isnan(ranges), [True, False, True, True, False, True, True])
    assert ranges[1] == 1.0 and ranges[4] == 30.0
    assert np.allclose(angles, [-0.5, -0.25, 0.0, 0.25, 0.5, 0.75, 1.0], atol=0, rtol=0)


def test_a_zero_reading_is_no_return_even_when_range_min_is_zero() -> None:
    """range_min = 0 (as albot1 convert writes, and many drivers) used to keep a 0.0 reading as a point at the
    laser; 0 is a driver's "no echo", a return at the laser's own window is impossible."""
    ranges, _ = scan_arrays(
        np.array([0.0, 1.0, 0.0], dtype=np.float32), angle_min=0.0, angle_increment=0.1, range_min=0.0, range_max=5.0
    )
    assert np.isnan(ranges).tolist() == [True, False, True]


def test_a_clockwise_scan_is_reversed_so_angles_ascend() -> None:
    ranges, angles = scan_arrays(
        np.array([1.0, 2.0, 3.0]), angle_min=0.5, angle_increment=-0.5, range_min=0.0, range_max=10.0
    )
    assert angles.tolist() == [-0.5, 0.0, 0.5]
    assert ranges.tolist() == [3.0, 2.0, 1.0]


@pytest.mark.parametrize("theta", [0.0, 0.3, -2.0, math.pi - 1e-9, -math.pi + 1e-9, 1.5])
def test_yaw_quaternion_round_trip(theta: float) -> None:
    assert yaw_from_quaternion(*quaternion_from_yaw(theta)) == pytest.approx(theta, abs=1e-12)


def test_yaw_of_an_unwrapped_heading_comes_back_wrapped() -> None:
    assert yaw_from_quaternion(*quaternion_from_yaw(2 * math.pi + 0.25)) == pytest.approx(0.25, abs=1e-12)


def test_stamp_conversions() -> None:
    ns = seconds_to_ns(70.2899)
    assert ns == 70_289_900_000
    assert split_ns(ns) == (70, 289_900_000)
    assert stamp_seconds(*split_ns(ns)) == pytest.approx(70.2899, abs=1e-12)


@pytest.mark.parametrize(
    ("seconds", "ns"),
    [(1700000000.75, 1_700_000_000_750_000_000), (1700000001.25, 1_700_000_001_250_000_000), (1.9999999999, 2 * 10**9)],
)
def test_unix_stamps_reach_the_bag_clock_exactly(seconds: float, ns: int) -> None:
    """``seconds * 1e9`` made 1700000000.75 s into ...750000128 ns (floats 256 ns apart at 1.7e18)."""
    assert seconds_to_ns(seconds) == ns
    if seconds != 1.9999999999:
        assert stamp_seconds(*split_ns(ns)) == seconds  # and read back as the same float


def test_pose_track_returns_stored_poses_exactly_at_their_stamps() -> None:
    poses = np.array([[0.0, 0.0, 3.0], [1.0, 2.0, 3.1], [2.0, 2.0, -3.1]])
    track = PoseTrack.build([1.0, 2.0, 3.0], poses)
    for t, pose in zip([1.0, 2.0, 3.0], poses):
        assert np.array_equal(track.at(t), pose)  # type: ignore[arg-type]


def test_pose_track_interpolates_heading_across_the_wrap() -> None:
    track = PoseTrack.build([0.0, 1.0], [[0.0, 0.0, math.pi - 0.1], [2.0, 4.0, -math.pi + 0.1]])
    mid = track.at(0.5)
    assert mid is not None
    assert mid[:2] == pytest.approx([1.0, 2.0])
    assert abs(abs(mid[2]) - math.pi) < 1e-12  # through pi, not through 0


def test_pose_track_never_extrapolates() -> None:
    track = PoseTrack.build([5.0, 1.0], [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])  # unsorted input is sorted
    assert track.start == 1.0 and track.end == 5.0
    assert track.at(0.999) is None and track.at(5.001) is None
    assert track.at(3.0) == pytest.approx([0.5, 0.0, 0.0])
