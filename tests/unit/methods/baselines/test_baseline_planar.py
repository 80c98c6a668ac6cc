"""Single-pose SE(2) helpers of the baselines against the vectorised albot1.geometry.se2."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.methods.baselines.planar import between, compose, planar_pose, pose_matrix


def test_compose_and_between_agree_with_se2() -> None:
    rng = np.random.default_rng(7)
    for _ in range(500):
        a = rng.uniform(-10, 10, 3)
        b = rng.uniform(-10, 10, 3)
        np.testing.assert_allclose(compose(a, b), se2.compose(a, b), atol=1e-12)
        np.testing.assert_allclose(between(a, b), se2.between(a, b), atol=1e-12)


def test_pose_matrix_round_trips_through_planar_pose() -> None:
    pose = np.array([3.0, -1.5, -2.9])
    matrix = pose_matrix(pose)
    np.testing.assert_allclose(matrix[:3, :3] @ [1.0, 0.0, 0.0], [math.cos(-2.9), math.sin(-2.9), 0.0])
    back, dropped = planar_pose(matrix)
    np.testing.assert_allclose(back, pose, atol=1e-15)
    assert dropped == 0.0


def test_planar_pose_drops_z_and_tilt() -> None:
    matrix = pose_matrix(np.array([1.0, -2.0, 0.5]))
    np.testing.assert_allclose(planar_pose(matrix)[0], [1.0, -2.0, 0.5])
    assert planar_pose(matrix)[1] == 0.0
    tilted = matrix.copy()
    tilted[2, 3] = 0.03
    c, s = math.cos(0.01), math.sin(0.01)
    tilted[:3, :3] = tilted[:3, :3] @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])  # 0.01 rad roll
    pose, dropped = planar_pose(tilted)
    np.testing.assert_allclose(pose, [1.0, -2.0, 0.5], atol=1e-4)
    assert dropped == pytest.approx(0.03)
