"""Turns learnt apart from straight steps when trusting the odometry (odometry_trust.OdometryTrust.kind)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.methods.baselines.gtsam_graph.odometry_trust import MAD_TO_SIGMA, OdometryTrust

STRAIGHT = np.array([0.5, 0.0, math.radians(3.0)])  # a node step that hardly turns
TURN = np.array([0.1, 0.05, math.radians(30.0)])  # a node step that turns 30 deg
MATCH_COV = np.diag([0.02**2, 0.02**2, math.radians(0.5) ** 2])  # the match floor of the default preset
MATCH_VAR = MATCH_COV[2, 2]


def _trust(turn_deg: float = 10.0) -> OdometryTrust:
    """Heading only, floor 1 x the match's (the default preset's), turns beyond ``turn_deg`` apart, 10 to veto."""
    return OdometryTrust(
        50, bias_z=3.0, gate_chi2=16.27, components=(2,), min_variance_ratio=1.0, turn_rad=math.radians(turn_deg)
    )


def _feed(trust: OdometryTrust, step: np.ndarray, n: int, dth_deg: float) -> None:
    """``n`` matches alternately +-``dth_deg`` off the odometry's heading step."""
    for k in range(n):
        sign = 1.0 if k % 2 else -1.0
        trust.add(step, step + np.array([0.0, 0.0, sign * math.radians(dth_deg)]))


def test_a_step_is_a_turn_when_its_odometry_turns_beyond_the_threshold_either_way() -> None:
    trust = _trust(10.0)
    assert trust.kind(STRAIGHT) == 0
    assert trust.kind(TURN) == 1
    assert trust.kind(-TURN) == 1
    assert trust.kind(np.array([0.0, 0.0, math.radians(10.0)])) == 0  # at the threshold: not beyond it
    assert OdometryTrust(50, 3.0, 16.27).kind(TURN) == 0  # turn_rad inf (the default): one population


def test_turns_whose_odometry_disagrees_more_are_not_trusted_while_straight_steps_lose_the_floor() -> None:
    """40 straight steps +-0.2 deg, 10 turns +-1 deg: pooled, the straight steps' spread would set the turns' weight.

    A turn is judged by the larger of the pooled and its own kind's variance: its own spread (1.48 deg) is far
    beyond what the match explains, so the match alone stands. A straight step is judged the same way (its own
    40 steps' sampling floor is the larger) and, learnt from its own kind, without the floor.
    """
    trust = _trust()
    _feed(trust, STRAIGHT, 40, 0.2)
    _feed(trust, TURN, 10, 1.0)
    spread = MAD_TO_SIGMA * math.radians(0.2)  # pooled: 40 of 50 at +-0.2 deg, so the MAD is 0.2 deg
    straight = trust.variances(np.diag(MATCH_COV), trust.kind(STRAIGHT))
    turn = trust.variances(np.diag(MATCH_COV), trust.kind(TURN))
    assert straight is not None and turn is not None
    assert straight[2] == pytest.approx(spread**2 * math.sqrt(2.0 / 40))  # own kind, n = 40; below the floor
    assert straight[2] < MATCH_VAR
    assert math.isinf(turn[2])
    assert trust.gated_variances(TURN, TURN, MATCH_COV) is None
    assert trust.gated_variances(STRAIGHT, STRAIGHT, MATCH_COV) is not None


def test_before_a_kind_has_ten_steps_its_steps_are_judged_on_the_pooled_history_with_the_floor() -> None:
    trust = _trust()
    _feed(trust, STRAIGHT, 41, 0.2)
    _feed(trust, TURN, 9, 1.0)
    turn = trust.variances(np.diag(MATCH_COV), trust.kind(TURN))
    assert turn is not None
    # pooled: median -0.2 deg, spread 1.4826 x 0.4 deg, so 0.35 - 0.25 = 0.10 deg^2 beyond the match's, lifted to 1 x it
    assert turn[2] == pytest.approx(MATCH_VAR)
    pooled = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=(2,), turn_rad=math.radians(10.0))
    _feed(pooled, STRAIGHT, 41, 0.2)
    _feed(pooled, TURN, 9, 1.0)
    unfloored = pooled.variances(np.diag(MATCH_COV), 1)
    assert unfloored is not None
    assert unfloored[2] == pytest.approx((MAD_TO_SIGMA * math.radians(0.4)) ** 2 - MATCH_VAR)


def test_one_population_keeps_the_pooled_history_and_the_floor() -> None:
    """turn_rad = inf: every step is of one kind and judged as before turns were learnt apart."""
    trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=(2,), min_variance_ratio=1.0)
    _feed(trust, STRAIGHT, 40, 0.2)
    _feed(trust, TURN, 10, 1.0)
    for step in (STRAIGHT, TURN):
        var = trust.variances(np.diag(MATCH_COV), trust.kind(step))
        assert var is not None and var[2] == pytest.approx(MATCH_VAR)
