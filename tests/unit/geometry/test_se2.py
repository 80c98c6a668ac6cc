"""SE(2) helpers: exact cases and algebraic identities."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2


def test_compose_known_case() -> None:
    a = np.array([1.0, 2.0, math.pi / 2])
    b = np.array([1.0, 0.0, 0.0])
    np.testing.assert_allclose(se2.compose(a, b), [1.0, 3.0, math.pi / 2], atol=1e-12)


def test_between_is_inverse_compose() -> None:
    a = np.array([1.0, -2.0, 0.3])
    b = np.array([4.0, 1.0, -2.9])
    np.testing.assert_allclose(se2.compose(a, se2.between(a, b)), b, atol=1e-12)
    np.testing.assert_allclose(se2.compose(se2.inverse(a), a), [0, 0, 0], atol=1e-12)


def test_matrix_round_trip() -> None:
    poses = np.array([[1.0, 2.0, 3.0], [-1.0, 0.5, -0.2]])
    np.testing.assert_allclose(se2.from_matrix(se2.to_matrix(poses)), poses, atol=1e-12)
    m = se2.to_matrix(poses[0]) @ se2.to_matrix(poses[1])
    np.testing.assert_allclose(se2.from_matrix(m), se2.compose(poses[0], poses[1]), atol=1e-12)


def test_transform_points_matches_matrix() -> None:
    pose = np.array([2.0, -1.0, 0.7])
    pts = np.array([[1.0, 0.0], [0.0, 2.0], [-3.0, 1.5]])
    homo = np.column_stack([pts, np.ones(3)]) @ se2.to_matrix(pose).T
    np.testing.assert_allclose(se2.transform_points(pose, pts), homo[:, :2], atol=1e-12)


def test_steps_round_trip() -> None:
    poses = np.array([[0, 0, 0], [1, 0, 0.1], [1.5, 0.4, 0.9], [1.0, 1.0, 3.1]], dtype=float)
    rebuilt = se2.integrate_steps(poses[0], se2.relative_steps(poses))
    np.testing.assert_allclose(rebuilt, poses, atol=1e-12)


def test_interpolate_across_the_angle_seam() -> None:
    t = np.array([0.0, 1.0])
    poses = np.array([[0.0, 0.0, math.pi - 0.1], [2.0, 0.0, -math.pi + 0.1]])
    mid = se2.interpolate(t, poses, [0.5])[0]
    assert mid[0] == pytest.approx(1.0)
    assert abs(abs(mid[2]) - math.pi) < 1e-9


def test_wrap_range() -> None:
    wrapped = se2.wrap(np.linspace(-20, 20, 1001))
    assert wrapped.min() >= -math.pi and wrapped.max() < math.pi


def test_path_length() -> None:
    assert se2.path_length(np.array([[0, 0, 0], [3, 4, 1], [3, 5, 2]], dtype=float)) == pytest.approx(6.0)


def test_bad_shape_is_rejected() -> None:
    with pytest.raises(ValueError, match="last axis of length 3"):
        se2.compose(np.zeros(2), np.zeros(3))
