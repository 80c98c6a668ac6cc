"""The weight floor held only on turning steps (OdometryTrust.floor_ratio, odometry_trust_floor_turn_deg)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.methods.baselines.gtsam_graph.odometry_trust import MAD_TO_SIGMA, OdometryTrust

STRAIGHT = np.array([0.5, 0.0, math.radians(3.0)])  # a node step turning 3 deg
TURN = np.array([0.1, 0.05, math.radians(30.0)])  # a node step turning 30 deg
MATCH_COV = np.diag([0.02**2, 0.02**2, math.radians(0.5) ** 2])  # the match floor of the default preset
MATCH_VAR = MATCH_COV[2, 2]


def _trust(floor_turn_deg: float) -> OdometryTrust:
    """Heading only, floor 1 x the match's (the default preset's), fed 40 steps +-0.2 deg off the odometry."""
    trust = OdometryTrust(
        50,
        bias_z=3.0,
        gate_chi2=16.27,
        components=(2,),
        min_variance_ratio=1.0,
        floor_turn_rad=math.radians(floor_turn_deg),
    )
    for k in range(40):
        step = STRAIGHT if k % 4 else TURN
        trust.add(step, step + np.array([0.0, 0.0, (1.0 if k % 2 else -1.0) * math.radians(0.2)]))
    return trust


def test_the_floor_ratio_holds_from_the_turn_on_either_way_and_everywhere_at_zero() -> None:
    trust = _trust(5.0)
    assert trust.floor_ratio(math.radians(3.0)) == 0.0
    assert trust.floor_ratio(math.radians(5.0)) == 1.0  # at the threshold: a turn
    assert trust.floor_ratio(math.radians(-30.0)) == 1.0
    assert _trust(0.0).floor_ratio(0.0) == 1.0  # 0 (the default preset): the floor on every step, as before


def test_a_straight_step_keeps_the_weight_its_odometry_earned_and_a_turn_is_floored_at_its_match() -> None:
    """Innovations +-0.2 deg: the odometry's learnt variance is the sampling floor of its spread, far below the
    match's (0.5 deg). A straight step gets that variance, a turn the match's own (never more weight than it);
    with the threshold at 0 both get the match's, the default preset's behaviour."""
    earned = (MAD_TO_SIGMA * math.radians(0.2)) ** 2 * math.sqrt(2.0 / 40)
    trust = _trust(5.0)
    straight = trust.gated_variances(STRAIGHT, STRAIGHT, MATCH_COV)
    turn = trust.gated_variances(TURN, TURN, MATCH_COV)
    assert straight is not None and turn is not None
    assert straight[2] == pytest.approx(earned)
    assert turn[2] == pytest.approx(MATCH_VAR)
    assert np.isinf(straight[:2]).all() and np.isinf(turn[:2]).all()  # heading only
    everywhere = _trust(0.0).gated_variances(STRAIGHT, STRAIGHT, MATCH_COV)
    assert everywhere is not None and everywhere[2] == pytest.approx(MATCH_VAR)


def test_without_the_floor_a_straight_step_far_off_its_match_fails_the_gate_the_floored_one_passes() -> None:
    """The earned variance is small, so the chi-square gate is tighter without the floor: a match 2.5 deg off a
    straight step is 3.5 joint sigma from the floored odometry (chi-square 12.5, passes 16.27) and 4.8 from the
    unfloored one (23.2, refused: the match alone stands)."""
    match = STRAIGHT + np.array([0.0, 0.0, math.radians(2.5)])
    assert _trust(0.0).gated_variances(STRAIGHT, match, MATCH_COV) is not None
    assert _trust(5.0).gated_variances(STRAIGHT, match, MATCH_COV) is None
