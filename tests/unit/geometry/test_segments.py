"""Segment geometry: exact distances, crossing tests and frame changes on hand-made cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.geometry.segments import (
    closest_parameter,
    line_angle,
    orientation,
    point_segment_distance,
    segment_distance,
    segments_cross,
    transform_segments,
)

A = np.array([0.0, 0.0, 4.0, 0.0])


def test_orientation_sign_says_which_side() -> None:
    assert orientation(0.0, 0.0, 4.0, 0.0, 1.0, 2.0) == 8.0  # left of a->b: positive, twice the area
    assert orientation(0.0, 0.0, 4.0, 0.0, 1.0, -2.0) == -8.0
    assert orientation(0.0, 0.0, 4.0, 0.0, 7.0, 0.0) == 0.0


@pytest.mark.parametrize(
    ("point", "t"), [((1.0, 3.0), 0.25), ((-2.0, 1.0), 0.0), ((9.0, -1.0), 1.0), ((4.0, 0.0), 1.0)]
)
def test_closest_parameter_is_clipped_to_the_segment(point: tuple[float, float], t: float) -> None:
    assert closest_parameter(point[0], point[1], 0.0, 0.0, 4.0, 0.0) == t


def test_closest_parameter_of_a_degenerate_segment_is_zero() -> None:
    assert closest_parameter(5.0, 5.0, 1.0, 1.0, 1.0, 1.0) == 0.0


def test_line_angle_ignores_direction() -> None:
    assert line_angle(0.0) == 0.0
    assert line_angle(math.pi) == pytest.approx(0.0, abs=1e-15)
    assert line_angle(-math.pi / 2) == pytest.approx(math.pi / 2)
    assert line_angle(math.radians(175.0)) == pytest.approx(math.radians(5.0))
    assert line_angle(math.radians(-365.0)) == pytest.approx(math.radians(5.0))


def test_point_segment_distance_perpendicular_and_beyond_the_ends() -> None:
    assert point_segment_distance(1.0, 3.0, A) == 3.0
    assert point_segment_distance(7.0, 4.0, A) == 5.0  # from the end (4, 0)
    assert point_segment_distance(-3.0, -4.0, A) == 5.0  # from the start
    assert point_segment_distance(2.0, 0.0, A) == 0.0


def test_crossing_segments_are_at_distance_zero() -> None:
    b = np.array([2.0, -1.0, 2.0, 1.0])
    assert segments_cross(A, b) and segments_cross(b, A)
    assert segment_distance(A, b) == 0.0


def test_parallel_collinear_and_skew_segments() -> None:
    assert not segments_cross(A, np.array([5.0, 0.0, 6.0, 0.0]))  # collinear never crosses
    assert segment_distance(A, np.array([5.0, 0.0, 6.0, 0.0])) == 1.0
    assert segment_distance(A, np.array([1.0, 2.0, 3.0, 2.0])) == 2.0  # parallel above
    assert segment_distance(A, np.array([6.0, 3.0, 7.0, 9.0])) == pytest.approx(math.hypot(2.0, 3.0))
    assert segment_distance(A, A) == 0.0


def test_segment_distance_is_symmetric_and_bounded_by_endpoint_distances() -> None:
    rng = np.random.default_rng(2)
    for _ in range(200):
        a, b = rng.uniform(-3, 3, 4), rng.uniform(-3, 3, 4)
        d = segment_distance(a, b)
        assert d == segment_distance(b, a)
        ends = min(math.hypot(*(a[i : i + 2] - b[j : j + 2])) for i in (0, 2) for j in (0, 2))
        assert 0.0 <= d <= ends + 1e-12


def test_transform_segments_moves_both_endpoints_like_points() -> None:
    pose = (2.0, -1.0, 0.7)
    segs = np.array([[1.0, 0.0, 0.0, 2.0], [-3.0, 1.5, 0.5, 0.5]])
    want = se2.transform_points(np.array(pose), segs.reshape(-1, 2)).reshape(-1, 4)
    np.testing.assert_allclose(transform_segments(pose, segs), want, atol=1e-12)
    assert transform_segments(pose, np.empty((0, 4))).shape == (0, 4)
