"""Point-to-line ICP on exact synthetic scans: known transforms are recovered, bad input is refused."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.synthetic.lidar import cast
from albot1.geometry import se2
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.gtsam_graph.errors import RegistrationError
from albot1.methods.baselines.gtsam_graph.registration import (
    IcpParams,
    Target,
    _linearise,
    line_normals,
    register,
    rotate,
    try_register,
)

# A 10 m x 6 m room with a pillar and an alcove: enough structure to fix x, y and theta.
WALLS = np.array(
    [
        [0, 0, 10, 0],
        [10, 0, 10, 6],
        [10, 6, 6, 6],
        [6, 6, 6, 7],
        [6, 7, 3, 7],
        [3, 7, 3, 6],
        [3, 6, 0, 6],
        [0, 6, 0, 0],
        [4, 2, 5, 2],
        [5, 2, 5, 3],
        [5, 3, 4, 3],
        [4, 3, 4, 2],
    ],
    dtype=float,
)
ANGLES = np.radians(np.linspace(-90.0, 90.0, 181))


def scan_points(pose: np.ndarray) -> np.ndarray:
    ranges = cast(WALLS, pose, ANGLES, 30.0)
    ok = np.isfinite(ranges)
    return np.column_stack([ranges[ok] * np.cos(ANGLES[ok]), ranges[ok] * np.sin(ANGLES[ok])])


@pytest.mark.parametrize("offset", [(0.2, -0.15, 5.0), (-0.3, 0.2, -8.0), (0.0, 0.0, 0.0)])
def test_known_transform_recovered_within_1cm_and_0_1deg(offset: tuple[float, float, float]) -> None:
    pose_a = np.array([2.0, 1.5, 0.3])
    pose_b = np.array([2.6, 1.9, 0.5])
    truth = se2.between(pose_a, pose_b)
    target = Target.from_points(scan_points(pose_a))
    guess = truth + np.array([offset[0], offset[1], math.radians(offset[2])])
    result = register(target, scan_points(pose_b), guess, IcpParams(prior_sigma_xy_m=10.0, prior_sigma_theta_rad=10.0))
    err = se2.between(truth, result.pose)
    assert result.converged
    assert math.hypot(err[0], err[1]) < 0.01
    assert abs(math.degrees(err[2])) < 0.1
    assert result.fitness > 0.8
    assert result.rmse_m < 0.01


def test_line_normals_are_perpendicular_to_a_wall() -> None:
    xs = np.linspace(0.0, 5.0, 51)
    points, normals = line_normals(np.column_stack([xs, np.full_like(xs, 2.0)]))
    assert len(points) == 51
    np.testing.assert_allclose(np.abs(normals[:, 1]), 1.0, atol=1e-9)
    np.testing.assert_allclose(normals[:, 0], 0.0, atol=1e-9)


def test_scattered_points_get_no_normals() -> None:
    rng = np.random.default_rng(3)
    points, _ = line_normals(rng.uniform(0.0, 1.0, size=(200, 2)), max_planarity=0.05)
    assert len(points) < 20


def test_information_reflects_a_corridor_degeneracy() -> None:
    """Two parallel walls constrain y and theta but not x: the information says so."""
    xs = np.linspace(-10.0, 10.0, 201)
    walls = np.concatenate(
        [np.column_stack([xs, np.full_like(xs, 1.0)]), np.column_stack([xs, np.full_like(xs, -1.0)])]
    )
    target = Target.from_points(walls)
    result = register(target, walls[::3] + np.array([0.05, 0.0]), np.zeros(3))
    info = result.information
    assert info[0, 0] < 1e-6 * info[1, 1]


def test_non_converging_registration_is_reported() -> None:
    target = Target.from_points(scan_points(np.array([2.0, 1.5, 0.3])))
    result = register(target, scan_points(np.array([2.6, 1.9, 0.5])), np.zeros(3), IcpParams(max_iterations=1))
    assert not result.converged


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ("nan_source", "source points must be finite"),
        ("few_points", "need at least 10 source points"),
        ("nan_guess", "initial guess must be finite"),
    ],
)
def test_unusable_input_raises_registration_error(bad: str, message: str) -> None:
    target = Target.from_points(scan_points(np.array([2.0, 1.5, 0.3])))
    source = scan_points(np.array([2.6, 1.9, 0.5]))
    guess = np.zeros(3)
    if bad == "nan_source":
        source[4] = np.nan
    elif bad == "few_points":
        source = source[:3]
    else:
        guess[1] = np.nan
    with pytest.raises(RegistrationError) as info:
        register(target, source, guess)
    assert isinstance(info.value, BaselineError)
    assert message in str(info.value)


def test_target_refuses_non_finite_points() -> None:
    with pytest.raises(RegistrationError, match="finite"):
        Target.from_points(np.array([[0.0, 0.0], [np.nan, 1.0], [1.0, 1.0]]))


def test_rotate_turns_row_vectors_counter_clockwise() -> None:
    """The one rotation of the package (ICP's linearisation, normals of a local map): R v per row."""
    vectors = np.array([[1.0, 0.0], [0.0, 2.0], [3.0, -4.0]])
    np.testing.assert_allclose(rotate(vectors, math.pi / 2), [[0.0, 1.0], [-2.0, 0.0], [4.0, 3.0]], atol=1e-15)
    np.testing.assert_allclose(
        rotate(vectors, 0.7), se2.transform_points(np.array([0.0, 0.0, 0.7]), vectors), rtol=0, atol=1e-15
    )


def test_try_register_is_none_below_the_minimum_points_and_register_otherwise() -> None:
    target = Target.from_points(scan_points(np.array([2.0, 1.5, 0.3])))
    source = scan_points(np.array([2.0, 1.5, 0.3]))
    params = IcpParams(min_points=10)
    assert try_register(target, source[:9], np.zeros(3), params) is None
    assert try_register(Target(np.empty((0, 2)), np.empty((0, 2))), source, np.zeros(3), params) is None
    found = try_register(target, source, np.zeros(3), params)
    expected = register(target, source, np.zeros(3), params)
    assert found is not None and np.array_equal(found.pose, expected.pose) and found.converged


@pytest.mark.parametrize("gate", [5.0, 0.05])
def test_linearisation_has_the_bits_of_the_per_array_formulation(gate: float) -> None:
    """The compiled correspondences and terms: the Jacobian, residuals, weights and weighted rows of numpy, bit for bit.

    A wide gate keeps every point (no selection), a narrow one drops some (the selection path).
    """
    target = Target.from_points(scan_points(np.array([2.0, 1.5, 0.3])))
    src = scan_points(np.array([2.6, 1.9, 0.5]))
    pose = se2.between(np.array([2.0, 1.5, 0.3]), np.array([2.6, 1.9, 0.5])) + np.array([0.03, -0.02, 0.01])
    jac, res, w, wj = _linearise(target, src, pose, gate, 0.1, 400.0)
    # The formulation every recorded result was computed with: separate gathers, the sum formed twice.
    rot = rotate(src, pose[2])
    assert target.tree is not None
    dist, idx = target.tree.query(rot + pose[:2], k=1, distance_upper_bound=gate)
    ok = dist < gate
    assert ok.all() == (gate > 1.0)
    rot, idx = rot[ok], idx[ok]
    n = target.normals[idx]
    diff = rot + pose[:2] - target.points[idx]
    expected_res = n[:, 0] * diff[:, 0] + n[:, 1] * diff[:, 1]
    expected_jac = np.empty((len(expected_res), 3))
    expected_jac[:, :2] = n
    expected_jac[:, 2] = n[:, 1] * rot[:, 0] - n[:, 0] * rot[:, 1]
    expected_w = 1.0 / (1.0 + (expected_res / 0.1) ** 2)
    assert len(res) > 10
    assert jac.tobytes() == expected_jac.tobytes()
    assert res.tobytes() == expected_res.tobytes()
    assert w.tobytes() == expected_w.tobytes()
    assert wj.tobytes() == (expected_jac * (expected_w * 400.0)[:, None]).tobytes()
