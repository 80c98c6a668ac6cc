"""The scalar SE(2) API against the vectorised one, the wrap convention, and the SE(3) bridge."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2


def test_wrap_angle_and_wrap_give_the_same_bits_in_minus_pi_to_pi() -> None:
    rng = np.random.default_rng(4)
    edges = [math.pi, -math.pi, 0.0, -0.0, 2 * math.pi, -2 * math.pi, 3 * math.pi, 1e-300, -1e-300, 1e10]
    edges += [math.nextafter(math.pi, 0.0), math.nextafter(-math.pi, 0.0)]
    angles = np.concatenate([rng.uniform(-50.0, 50.0, 20_000), rng.uniform(-4.0, 4.0, 20_000), edges])
    vectorised = se2.wrap(angles)
    scalar = np.array([se2.wrap_angle(a) for a in angles.tolist()])
    assert np.array_equal(vectorised.view(np.int64), scalar.view(np.int64))
    assert vectorised.min() >= -math.pi and vectorised.max() < math.pi
    assert se2.wrap_angle(math.pi) == -math.pi  # the half-open end
    assert se2.wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2, abs=1e-15)


def test_compose_and_between_agree_with_the_vectorised_forms() -> None:
    rng = np.random.default_rng(7)
    for _ in range(500):
        a = rng.uniform(-10, 10, 3)
        b = rng.uniform(-10, 10, 3)
        np.testing.assert_allclose(se2.compose_pose(a, b), se2.compose(a, b), atol=1e-12)
        np.testing.assert_allclose(se2.between_pose(a, b), se2.between(a, b), atol=1e-12)
        # The heading goes through the one wrap: same bits in both forms.
        assert se2.compose_pose(a, b)[2] == se2.compose(a, b)[2]
        assert se2.between_pose(a, b)[2] == se2.between(a, b)[2]


def test_scalar_poses_are_plain_float_triples_from_tuples_or_arrays() -> None:
    got = se2.compose_pose((1.0, 2.0, math.pi / 2), np.array([1.0, 0.0, 0.0]))
    assert isinstance(got, tuple) and len(got) == 3
    assert got == pytest.approx((1.0, 3.0, math.pi / 2), abs=1e-12)
    assert se2.between_pose(got, got) == (0.0, 0.0, 0.0)


def test_pose_to_se3_round_trips_through_pose_from_se3() -> None:
    pose = np.array([3.0, -1.5, -2.9])
    matrix = se2.pose_to_se3(pose)
    np.testing.assert_allclose(matrix[:3, :3] @ [1.0, 0.0, 0.0], [math.cos(-2.9), math.sin(-2.9), 0.0])
    back, dropped = se2.pose_from_se3(matrix)
    np.testing.assert_allclose(back, pose, atol=1e-15)
    assert dropped == 0.0
    np.testing.assert_allclose(matrix[:3, :3][:2, :2], se2.to_matrix(pose)[:2, :2])


def test_pose_from_se3_drops_z_and_tilt() -> None:
    matrix = se2.pose_to_se3(np.array([1.0, -2.0, 0.5]))
    tilted = matrix.copy()
    tilted[2, 3] = 0.03
    c, s = math.cos(0.01), math.sin(0.01)
    tilted[:3, :3] = tilted[:3, :3] @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])  # 0.01 rad roll
    pose, dropped = se2.pose_from_se3(tilted)
    np.testing.assert_allclose(pose, [1.0, -2.0, 0.5], atol=1e-4)
    assert dropped == pytest.approx(0.03)
