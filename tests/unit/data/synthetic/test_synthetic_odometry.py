"""Simulated odometry: exact without error, exact systematic errors, seeded random walk."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.synthetic.errors import SyntheticWorldError
from albot1.data.synthetic.odometry import OdometryErrorModel, perturb_steps, simulate
from albot1.data.synthetic.route import CONTINUOUS, START_STOP, Route, sample
from albot1.geometry import se2

LOOP = sample(Route(((1.0, 2.0), (6.0, 2.0), (6.0, 5.0), (1.0, 5.0), (1.0, 2.0)), closed=True), START_STOP)
NOISY = OdometryErrorModel(
    sigma_distance=0.02,
    sigma_lateral=0.01,
    sigma_turn=0.03,
    sigma_drift=0.01,
    distance_scale=1.02,
    turn_scale=0.98,
    heading_bias=0.002,
)


def _straight(length: float, step: float) -> np.ndarray:
    n = int(round(length / step))
    return np.column_stack([np.linspace(0.0, length, n + 1), np.zeros(n + 1), np.zeros(n + 1)])


def test_exact_model_reproduces_the_truth() -> None:
    np.testing.assert_allclose(simulate(LOOP, OdometryErrorModel.exact(), seed=0), LOOP, atol=1e-12)


def test_odometry_starts_at_the_true_first_pose() -> None:
    np.testing.assert_array_equal(simulate(LOOP, NOISY, seed=4)[0], LOOP[0])


def test_distance_scale_stretches_a_straight_line_exactly() -> None:
    got = simulate(_straight(10.0, 1.0), OdometryErrorModel(distance_scale=1.1), seed=0)
    np.testing.assert_allclose(got[:, 0], 1.1 * np.arange(11.0), atol=1e-12)
    np.testing.assert_allclose(got[:, 1:], 0.0, atol=1e-12)


def test_turn_scale_over_reports_turns_exactly() -> None:
    got = simulate(LOOP, OdometryErrorModel(turn_scale=1.02), seed=0)
    turned = np.sum(se2.relative_steps(got)[:, 2])
    assert turned == pytest.approx(1.02 * 2 * math.pi, abs=1e-12)


def test_heading_bias_accumulates_per_metre() -> None:
    bias = math.radians(0.5)
    got = simulate(_straight(10.0, 1.0), OdometryErrorModel(heading_bias=bias), seed=0)
    np.testing.assert_allclose(got[:, 2], bias * np.arange(11.0), atol=1e-12)


def test_same_seed_same_odometry_and_different_seed_different() -> None:
    a = simulate(LOOP, NOISY, seed=1)
    np.testing.assert_array_equal(a, simulate(LOOP, NOISY, seed=1))
    assert not np.allclose(a, simulate(LOOP, NOISY, seed=2))
    np.testing.assert_array_equal(a, simulate(LOOP, NOISY, seed=np.random.default_rng(1)))


def test_random_error_grows_like_a_random_walk_whatever_the_scan_spacing() -> None:
    """Variance proportional to the motion: a 10 m leg ends with the same spread in 0.1 m or 1 m steps."""
    model = OdometryErrorModel(sigma_distance=0.05)
    rng = np.random.default_rng(0)
    for step in (0.1, 1.0):
        steps = se2.relative_steps(_straight(10.0, step))
        ends = np.array([perturb_steps(steps, model, rng)[:, 0].sum() for _ in range(3000)])
        assert float(np.std(ends)) == pytest.approx(0.05 * math.sqrt(10.0), rel=0.06)
        assert abs(float(np.mean(ends)) - 10.0) < 4 * 0.05 * math.sqrt(10.0) / math.sqrt(3000)


def test_turn_noise_only_acts_on_turns() -> None:
    model = OdometryErrorModel(sigma_turn=0.1)
    straight = _straight(5.0, 0.5)
    np.testing.assert_allclose(simulate(straight, model, seed=3), straight, atol=1e-12)
    turning = sample(Route(((0.0, 0.0), (1.0, 0.0), (1.0, 1.0))), CONTINUOUS)
    assert not np.allclose(simulate(turning, model, seed=3)[:, 2], turning[:, 2])


def test_empty_and_single_pose_trajectories() -> None:
    assert simulate(np.empty((0, 3)), NOISY, seed=0).shape == (0, 3)
    np.testing.assert_array_equal(simulate(np.array([[1.0, 2.0, 0.5]]), NOISY, seed=0), [[1.0, 2.0, 0.5]])


@pytest.mark.parametrize(
    ("field", "value"), [("sigma_distance", -0.1), ("sigma_turn", math.nan), ("distance_scale", math.inf)]
)
def test_bad_models(field: str, value: float) -> None:
    with pytest.raises(SyntheticWorldError, match=field):
        OdometryErrorModel(**{field: value})


def test_model_as_dict_lists_every_parameter() -> None:
    assert NOISY.as_dict()["heading_bias"] == 0.002
    assert set(NOISY.as_dict()) == {
        "sigma_distance",
        "sigma_lateral",
        "sigma_turn",
        "sigma_drift",
        "distance_scale",
        "turn_scale",
        "heading_bias",
    }
