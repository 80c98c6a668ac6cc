"""The earned choice: a step whose odometry and match disagree keeps the side with the smaller earned variance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.earned_choice import EarnedFactors, choose
from albot1.methods.baselines.gtsam_graph.odometry_trust import UNTRUSTED_VARIANCE, OdometryTrust
from albot1.methods.registry import resolve_config

STEP = np.array([0.5, 0.0, math.radians(3.0)])  # one node step of odometry, previous node's frame
DEG2 = math.radians(1.0) ** 2
#: The match's stated heading variance, (0.5 deg)^2: the match floor of the default preset.
MATCH_COV = np.diag([0.02**2, 0.02**2, 0.25 * DEG2])
#: A history of heading innovations alternating +-0.3 deg: median 0, MAD 0.3 deg, so a spread of 1.4826 x 0.3 deg;
#: its square (0.19784 deg^2) less the match's 0.25 is negative, so the odometry earns its sampling floor,
#: spread^2 x sqrt(2 / 50) = 0.2 x spread^2 (no bias: the median is 0).
SPREAD2 = (1.4826 * 0.3) ** 2 * DEG2
EARNED = 0.2 * SPREAD2


def _trust(components: tuple[int, ...] = (2,), xy_m: float = 0.0) -> OdometryTrust:
    """50 matched steps of the history above (heading only as the default preset; or x, y too at +-``xy_m``)."""
    trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=components, bias_horizon=50, min_variance_ratio=1)
    for k in range(50):
        sign = 1.0 if k % 2 else -1.0
        trust.add(STEP, STEP + sign * np.array([xy_m, xy_m, math.radians(0.3)]))
    return trust


def _turned(deg: float) -> np.ndarray:
    return STEP + np.array([0.0, 0.0, math.radians(deg)])


def test_a_step_that_agrees_within_the_level_is_judged_as_before_with_the_floor() -> None:
    # 0.5 deg: (0.5)^2 / (0.25 + 0.0396) = 0.86 < 3.84 (chi-square 1 dof, 95 %)
    choice = choose(_trust(), STEP, _turned(0.5), MATCH_COV, 0.95)
    assert choice.kind == "as before"
    assert choice.odometry_covariance is not None
    assert choice.odometry_covariance == pytest.approx(np.diag([UNTRUSTED_VARIANCE, UNTRUSTED_VARIANCE, 0.25 * DEG2]))
    assert np.array_equal(choice.match_covariance, MATCH_COV)


def test_a_disagreement_beyond_the_level_keeps_the_odometry_that_earned_less_and_grows_the_match() -> None:
    # 2 deg: 4 / 0.2896 = 13.8 > 3.84, but within today's gate (4 / 0.5 = 8 <= 16.27, floored variances)
    choice = choose(_trust(), STEP, _turned(2.0), MATCH_COV, 0.95)
    assert choice.kind == "odometry"
    assert choice.odometry_covariance is not None
    assert choice.odometry_covariance == pytest.approx(np.diag([UNTRUSTED_VARIANCE, UNTRUSTED_VARIANCE, EARNED]))
    # the match's heading variance becomes the disagreement squared, (2 deg)^2; its translation is left alone
    assert choice.match_covariance == pytest.approx(np.diag([0.02**2, 0.02**2, 4.0 * DEG2]))


def test_the_threshold_is_the_chi_square_quantile_of_the_level() -> None:
    # the boundary at 95 %, 1 dof: d^2 = 3.8415 x (0.25 deg^2 + earned)
    boundary = math.sqrt(3.841459 * (0.25 * DEG2 + EARNED))
    below = choose(_trust(), STEP, STEP + np.array([0.0, 0.0, 0.999 * boundary]), MATCH_COV, 0.95)
    above = choose(_trust(), STEP, STEP + np.array([0.0, 0.0, 1.001 * boundary]), MATCH_COV, 0.95)
    assert (below.kind, above.kind) == ("as before", "odometry")
    assert choose(_trust(), STEP, STEP + np.array([0.0, 0.0, 1.001 * boundary]), MATCH_COV, 0.99).kind == "as before"


def test_a_disagreement_beyond_todays_outlier_gate_stays_as_before_no_factor() -> None:
    # 4 deg: 16 / 0.5 = 32 > 16.27 with the floored variances: one of them is an outlier, the match stands
    choice = choose(_trust(), STEP, _turned(4.0), MATCH_COV, 0.95)
    assert choice.kind == "as before"
    assert choice.odometry_covariance is None
    assert np.array_equal(choice.match_covariance, MATCH_COV)


def test_an_odometry_that_earned_no_trust_gets_no_factor_however_it_disagrees() -> None:
    """Every match 1 deg off the odometry (+-0.1 deg): a biased odometry is never trusted, so nothing is chosen."""
    trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=(2,), bias_horizon=50, min_variance_ratio=1)
    for k in range(50):
        trust.add(STEP, _turned(1.0 + (0.1 if k % 2 else -0.1)))
    for deg in (0.5, 2.0):
        choice = choose(trust, STEP, _turned(deg), MATCH_COV, 0.95)
        assert choice.kind == "as before" and choice.odometry_covariance is None


#: A match that is well constrained along (1, 1) / sqrt(2) in x, y (variance 4e-4 - 3.9e-4 = 1e-5 m^2) and
#: degenerate along (1, -1) / sqrt(2) (7.9e-4 m^2): a corridor along that diagonal.
CORRIDOR = np.array([[4e-4, -3.9e-4, 0.0], [-3.9e-4, 4e-4, 0.0], [0.0, 0.0, 0.25 * DEG2]])
#: x and y innovations alternating +-0.01 m: each earns 0.2 x (1.4826 x 0.01)^2 = 4.396e-5 m^2 (its sampling floor).
EARNED_XY = 0.2 * (1.4826 * 0.01) ** 2


def test_the_match_wins_where_it_is_constrained_along_the_disagreement() -> None:
    # 0.03 m along (1, 1): match variance there 1e-5 < the odometry's 4.396e-5; chi-square 3 dof (7.81) exceeded
    # with the earned variances (1.8e-3 / 5.396e-5 = 33) but not today's gate (1.8e-3 / 4.1e-4 = 4.4 <= 16.27)
    choice = choose(_trust((0, 1, 2), 0.01), STEP, STEP + np.array([0.03, 0.03, 0.0]), CORRIDOR, 0.95)
    assert choice.kind == "match"
    assert choice.odometry_covariance is None
    assert np.array_equal(choice.match_covariance, CORRIDOR)


def test_the_odometry_wins_along_the_matchs_degenerate_direction_and_the_match_grows_there_only() -> None:
    # 0.07 m along (1, -1): match variance there 7.9e-4 > 4.396e-5; 9.8e-3 / 8.34e-4 = 11.75 > 7.81, and today's
    # gate passes it (9.8e-3 / 1.19e-3 = 8.2)
    choice = choose(_trust((0, 1, 2), 0.01), STEP, STEP + np.array([0.07, -0.07, 0.0]), CORRIDOR, 0.95)
    assert choice.kind == "odometry"
    assert choice.odometry_covariance is not None
    assert choice.odometry_covariance == pytest.approx(np.diag([EARNED_XY, EARNED_XY, EARNED]))
    u = np.array([1.0, -1.0, 0.0]) / math.sqrt(2.0)
    grown = choice.match_covariance
    assert u @ grown @ u == pytest.approx(2 * 0.07**2)  # the disagreement squared along it
    w = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)
    assert w @ grown @ w == pytest.approx(1e-5)  # unchanged across it
    assert grown[2, 2] == pytest.approx(0.25 * DEG2)


def test_earned_factors_give_the_newest_node_its_grown_match_and_count_the_choices() -> None:
    counters: dict[str, int] = {}
    factors = EarnedFactors(
        OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=(2,), bias_horizon=50, min_variance_ratio=1),
        0.95,
        counters,
    )
    for key in range(1, 51):
        judged = factors.add(key, STEP, _turned(0.3 if key % 2 else -0.3), MATCH_COV)
        assert factors.match_covariance(key, MATCH_COV) is MATCH_COV
    assert [f.key for f in judged] == [50]
    assert counters == {}  # no choice made yet: no counter (a run without one keeps its counters)
    (factor,) = factors.add(51, STEP, _turned(2.0), MATCH_COV)
    assert factor.key == 51 and factor.covariance[2, 2] < 0.25 * DEG2
    assert factors.match_covariance(51, MATCH_COV)[2, 2] == pytest.approx(4.0 * DEG2)
    assert factors.match_covariance(51, MATCH_COV) is MATCH_COV  # asked once per node: nothing is kept after
    assert counters == {"odometry_earned_odometry": 1}


def test_the_level_is_off_in_the_preset_and_bounded() -> None:
    cfg = resolve_config("gtsam-graph", "default", {})
    assert isinstance(cfg, GtsamGraphConfig)
    assert cfg.odometry_trust_earned_level == 0.0
    with pytest.raises(ValidationError):
        GtsamGraphConfig.model_validate({**cfg.model_dump(), "odometry_trust_earned_level": 1.0})
    with pytest.raises(ValidationError, match="odometry_trust_earned_level needs odometry_trust_factors"):
        GtsamGraphConfig.model_validate(
            {**cfg.model_dump(), "odometry_trust_earned_level": 0.99, "odometry_trust_factors": False}
        )
