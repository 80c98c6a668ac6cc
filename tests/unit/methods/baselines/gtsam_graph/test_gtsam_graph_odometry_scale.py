"""The odometry's heading scale error learnt from every matched step (TurnScale, odometry_trust_turn_scale)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.methods.baselines.gtsam_graph.odometry_scale import TurnScale
from albot1.methods.baselines.gtsam_graph.odometry_trust import OdometryTrust

EPS = math.radians(0.2)  # the white part of every innovation: +-0.2 deg, alternating
TURNS = np.radians([0.0, 0.0, 2.0, 2.0, -2.0, -2.0, 30.0, 30.0, -30.0, -30.0] * 5)  # pairs: the +- cancel
MATCH_COV = np.diag([0.02**2, 0.02**2, math.radians(0.5) ** 2])  # the match floor of the default preset


def _scale(scale: float, outlier_rad: float = 0.0) -> TurnScale:
    """A TurnScale fed innovations ``scale * turn +- EPS`` (and, if given, one more step turning 30 deg that many
    radians further off)."""
    learnt = TurnScale(bias_z=3.0, bias_horizon=50)
    for k, turn in enumerate(TURNS):
        learnt.add(float(turn), scale * float(turn) + (EPS if k % 2 else -EPS))
    if outlier_rad:
        learnt.add(math.radians(30.0), scale * math.radians(30.0) + outlier_rad)
    return learnt


def test_a_scale_error_is_recovered_exactly_with_its_heteroscedasticity_consistent_standard_error() -> None:
    """Equal turns carry opposite white errors, so the slope is the scale itself; every residual is +-EPS (none
    clipped), so White's standard error is EPS / sqrt(sum of squared turns)."""
    scale, standard_error = _scale(0.012).estimate()
    assert scale == pytest.approx(0.012, abs=1e-12)
    assert standard_error == pytest.approx(EPS / math.sqrt(float(TURNS @ TURNS)))


def test_a_bad_match_in_a_turn_moves_the_slope_by_its_clipped_residual_only() -> None:
    """One step 10 deg off in a 30 deg turn: least squares would move the slope by 10 deg x 30 deg / sum t^2
    (0.016); the winsorised fit clips that residual to a few robust sigmas (0.2 deg each) and moves far less."""
    clean = _scale(0.0)
    bad = _scale(0.0, outlier_rad=math.radians(10.0))
    turned = float(TURNS @ TURNS) + math.radians(30.0) ** 2
    unclipped = math.radians(10.0) * math.radians(30.0) / turned
    shift = bad.estimate()[0] - clean.estimate()[0]
    assert clean.estimate()[0] == pytest.approx(0.0, abs=1e-12)
    assert 0.0 < shift < unclipped / 5.0
    assert unclipped == pytest.approx(0.0158, abs=1e-4)


def test_a_scale_within_its_standard_errors_counts_nothing_a_significant_one_its_debiased_square() -> None:
    standard_error = EPS / math.sqrt(float(TURNS @ TURNS))
    assert _scale(2.0 * standard_error).squared_scale() == 0.0  # 2 standard errors: not significant at 3
    assert _scale(0.0).variance(math.radians(30.0)) == 0.0
    learnt = _scale(0.012)  # 0.012 is 6.6 standard errors
    expected = 0.012**2 - standard_error**2
    assert learnt.squared_scale() == pytest.approx(expected)
    assert learnt.variance(math.radians(30.0)) == pytest.approx(50 * expected * math.radians(30.0) ** 2)
    assert learnt.variance(0.0) == 0.0  # a straight step: nothing


def test_no_turn_or_no_spread_is_no_evidence() -> None:
    learnt = TurnScale(bias_z=3.0, bias_horizon=50)
    assert learnt.estimate() == (0.0, math.inf)
    for _ in range(5):
        learnt.add(0.0, EPS)
    assert learnt.estimate() == (0.0, math.inf)
    assert learnt.squared_scale() == 0.0


def _trust(scale: float, turn_scale: bool) -> OdometryTrust:
    """Heading only, no floor, 50 steps of innovations ``scale * turn +- EPS``."""
    trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=(2,), bias_horizon=50, turn_scale=turn_scale)
    for k, turn in enumerate(TURNS):
        step = np.array([0.5, 0.0, float(turn)])
        match = step - np.array([0.0, 0.0, scale * float(turn) + (EPS if k % 2 else -EPS)])
        trust.add(step, match)
    return trust


def test_a_mis_scaled_odometry_keeps_its_straight_steps_and_loses_its_turns() -> None:
    """1.2 % too far per turn: a straight step keeps the variance the window earned, a 30 deg turn gets the scale's
    accumulated variance on top, which exceeds the match's: that turn's odometry is not trusted (no factor)."""
    straight = np.array([0.5, 0.0, 0.0])
    turn = np.array([0.5, 0.0, math.radians(30.0)])
    off = _trust(0.012, turn_scale=False)
    on = _trust(0.012, turn_scale=True)
    earned = off.gated_variances(straight, straight, MATCH_COV)
    assert earned is not None
    kept = on.gated_variances(straight, straight, MATCH_COV)
    assert kept is not None and kept[2] == pytest.approx(earned[2])
    assert off.gated_variances(turn, turn, MATCH_COV) is not None  # judged by the straight steps' spread
    assert on.gated_variances(turn, turn, MATCH_COV) is None


def test_an_odometry_without_scale_error_is_judged_as_without_the_rule() -> None:
    for heading in np.radians([0.0, 2.0, 30.0, -10.0]):
        step = np.array([0.5, 0.0, heading])
        with_rule = _trust(0.0, turn_scale=True).gated_variances(step, step, MATCH_COV)
        without = _trust(0.0, turn_scale=False).gated_variances(step, step, MATCH_COV)
        assert with_rule is not None and without is not None
        np.testing.assert_array_equal(with_rule, without)
