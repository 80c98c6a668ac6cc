"""Gating the tracker's velocity guess against the odometry (albot1.methods.baselines.gtsam_graph.gating)."""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph.gating import CorrectionScale, turn_agrees, velocity_match_allowed


def _pose(x: float, y: float, deg: float) -> np.ndarray:
    return np.array([x, y, math.radians(deg)])


def test_fhw_in_place_turn_the_velocity_match_is_rejected_when_the_odometry_match_passed() -> None:
    """fhw-corrected scan 59: odometry +63.4 deg in place (right); the velocity match sits 94.9 deg away."""
    track = _pose(2.0, 1.0, 10.0)
    guess = se2.compose(track, _pose(0.09, 0.15, 63.4))  # the odometry increment
    wrong = se2.compose(guess, _pose(-0.01, 0.09, -94.9))  # what ICP from the velocity guess converged to
    assert not velocity_match_allowed(wrong, guess, odometry_match_passed=True, max_turn_deg=20.0)
    # the same match may win where the odometry guess gave no passing match (a stalled odometry's catch-up)
    assert velocity_match_allowed(wrong, guess, odometry_match_passed=False, max_turn_deg=20.0)


def test_a_velocity_match_within_the_wide_gate_competes_on_fit() -> None:
    guess = _pose(0.0, 0.0, 170.0)
    near = se2.compose(guess, _pose(0.3, 0.0, 19.9))  # wraps past +180 deg: the turn is still 19.9 deg
    assert velocity_match_allowed(near, guess, odometry_match_passed=True, max_turn_deg=20.0)
    assert not velocity_match_allowed(se2.compose(guess, _pose(0.0, 0.0, -20.1)), guess, True, 20.0)


def test_turn_agreement_ignores_translation_and_is_symmetric_in_sign() -> None:
    guess = _pose(1.0, -1.0, -45.0)
    assert turn_agrees(se2.compose(guess, _pose(5.0, 5.0, 0.0)), guess, 0.0)
    assert turn_agrees(se2.compose(guess, _pose(0.0, 0.0, 10.0)), guess, 10.0 + 1e-9)
    assert not turn_agrees(se2.compose(guess, _pose(0.0, 0.0, -10.0)), guess, 9.99)


def test_a_correction_far_beyond_the_recent_ones_is_an_outlier_once_enough_are_known() -> None:
    scale = CorrectionScale(window=50, floor_m=0.02, floor_deg=0.5)
    jump = _pose(0.23, 0.0, -6.0)  # fhw-corrected scan 59 with perfect odometry: 0.23 m / 6 deg, fit 0.49
    assert not scale.is_outlier(jump, 5.0)  # nothing known yet (fewer than window // 5 corrections)
    for k in range(10):
        scale.add(_pose(0.01 * (k % 3), 0.005, 0.2 * (-1) ** k))  # centimetres, 0.2 deg: good odometry
    assert scale.is_outlier(jump, 5.0)
    assert not scale.is_outlier(jump, 0.0)  # factor 0: off
    # the floors: 5 x max(0.02 m, median) = 0.1 m and 5 x 0.5 deg = 2.5 deg
    assert not scale.is_outlier(_pose(0.099, 0.0, 2.49), 5.0)
    assert scale.is_outlier(_pose(0.101, 0.0, 0.0), 5.0) and scale.is_outlier(_pose(0.0, 0.0, -2.51), 5.0)


def test_the_scale_follows_an_odometry_that_is_often_wrong() -> None:
    """mit-csail-like: corrections of several degrees are the rule, so a 12 deg one is not an outlier."""
    scale = CorrectionScale(window=50, floor_m=0.02, floor_deg=0.5)
    for k in range(60):
        scale.add(_pose(0.05, 0.0, 4.0 * (-1) ** k))
    assert not scale.is_outlier(_pose(0.2, 0.0, 12.0), 5.0)
    assert scale.is_outlier(_pose(0.0, 0.0, 21.0), 5.0)
