"""Fusing the odometry step into a node's matched edge (albot1.methods.baselines.gtsam_graph.odometry_trust)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.methods.baselines.gtsam_graph.odometry_trust import (
    MAD_TO_SIGMA,
    MEDIAN_EFFICIENCY,
    OdometryTrust,
    innovation,
    min_history,
    squared_bias,
)

STEP = np.array([0.5, 0.02, math.radians(3.0)])  # one node step of odometry, previous node's frame
MATCH_COV = np.diag([0.02**2, 0.02**2, math.radians(0.5) ** 2])  # the match floor of the default preset


def _fed(offsets: list[tuple[float, float, float]], window: int = 50) -> OdometryTrust:
    """A trust whose history holds matches at these (dx m, dy m, dtheta deg) from the odometry step."""
    trust = OdometryTrust(window, bias_z=3.0, gate_chi2=16.27)
    for dx, dy, dth in offsets:
        trust.add(STEP, STEP + np.array([dx, dy, math.radians(dth)]))
    return trust


def _alternating(n: int, dx: float, dy: float, dth: float) -> list[tuple[float, float, float]]:
    return [(s * dx, s * dy, s * dth) for s in (1.0 if k % 2 else -1.0 for k in range(n))]


def test_nothing_is_fused_until_the_bias_test_has_the_power_to_find_a_bias_as_large_as_the_spread() -> None:
    """(3 + 2)^2 * pi / 2 = 39.3 -> 40 matched steps (fhw-corrected[::3] fused 9 biased headings on 10)."""
    assert min_history(3.0) == 40
    assert min_history(1.0) == 15
    trust = _fed(_alternating(39, 0.017, 0.017, 0.45))
    assert trust.variances(np.diag(MATCH_COV)) is None
    assert trust.fuse(STEP, STEP, MATCH_COV) is None
    trust.add(STEP, STEP)
    assert trust.variances(np.diag(MATCH_COV)) is not None


def test_white_disagreement_gives_the_odometry_what_the_matches_do_not_claim() -> None:
    """Innovations +-0.017 m / +-0.45 deg about 0: spread 1.4826 x MAD; the odometry gets spread^2 - match variance."""
    trust = _fed(_alternating(40, 0.017, 0.017, 0.45))
    var = trust.variances(np.diag(MATCH_COV))
    assert var is not None
    spread_xy, spread_th = MAD_TO_SIGMA * 0.017, MAD_TO_SIGMA * math.radians(0.45)
    assert var[0] == pytest.approx(spread_xy**2 - 0.02**2)
    assert var[1] == pytest.approx(spread_xy**2 - 0.02**2)
    assert var[2] == pytest.approx(spread_th**2 - math.radians(0.5) ** 2)


def test_an_odometry_worse_than_the_matches_is_not_fused() -> None:
    """+-0.03 m / +-0.8 deg: what the matches do not explain exceeds their own variance; the match alone stands."""
    trust = _fed(_alternating(40, 0.03, 0.03, 0.8))
    var = trust.variances(np.diag(MATCH_COV))
    assert var is not None and np.isinf(var).all()
    assert trust.fuse(STEP, STEP + np.array([0.01, 0.0, 0.0]), MATCH_COV) is None
    # the boundary: heading spread^2 - 0.5^2 deg^2 equal to 0.5^2 deg^2 (spread 0.5 sqrt(2) deg) is not below it
    edge = math.sqrt(2.0) * 0.5 / MAD_TO_SIGMA
    var = _fed(_alternating(40, 0.02, 0.02, edge * (1 + 1e-6))).variances(np.diag(MATCH_COV))
    assert var is not None and math.isinf(var[2])
    var = _fed(_alternating(40, 0.02, 0.02, edge * (1 - 1e-6))).variances(np.diag(MATCH_COV))
    assert var is not None and var[2] < MATCH_COV[2, 2]


def test_a_spread_the_matches_explain_leaves_the_odometry_its_sampling_floor() -> None:
    """Perfect odometry: the disagreement is the matches' own error, so the odometry is nearly rigid, not rigid."""
    trust = _fed(_alternating(40, 0.01, 0.01, 0.2))
    var = trust.variances(np.diag(MATCH_COV))
    assert var is not None
    spread_th = MAD_TO_SIGMA * math.radians(0.2)
    assert var[2] == pytest.approx(spread_th**2 * math.sqrt(2.0 / 40))


def test_the_fused_step_is_the_information_weighted_mean() -> None:
    trust = _fed(_alternating(40, 0.017, 0.017, 0.45))
    var = trust.variances(np.diag(MATCH_COV))
    assert var is not None
    match = STEP + np.array([0.03, -0.02, math.radians(0.8)])
    fused = trust.fuse(STEP, match, MATCH_COV)
    assert fused is not None
    pose, cov = fused
    for k in range(3):
        w_match, w_odo = 1.0 / MATCH_COV[k, k], 1.0 / var[k]
        assert pose[k] == pytest.approx((w_match * match[k] + w_odo * STEP[k]) / (w_match + w_odo))
        assert cov[k, k] == pytest.approx(1.0 / (w_match + w_odo))
    assert np.allclose(cov, np.diag(np.diag(cov)))


def test_a_biased_component_is_not_fused_the_others_are() -> None:
    """A heading bias (every match 0.5 deg off the odometry, +-0.1 deg): fusing it would turn the map by its share."""
    offsets = [(dx, dy, 0.5 + dth) for dx, dy, dth in _alternating(40, 0.017, 0.017, 0.1)]
    trust = _fed(offsets)
    var = trust.variances(np.diag(MATCH_COV))
    assert var is not None and math.isinf(var[2]) and np.isfinite(var[:2]).all()
    match = STEP + np.array([0.02, 0.0, math.radians(0.5)])
    fused = trust.fuse(STEP, match, MATCH_COV)
    assert fused is not None
    pose, cov = fused
    assert pose[2] == match[2] and cov[2, 2] == pytest.approx(MATCH_COV[2, 2])
    assert STEP[0] < pose[0] < match[0]


def test_a_step_beyond_the_gate_keeps_the_match() -> None:
    trust = _fed(_alternating(40, 0.017, 0.017, 0.45))
    assert trust.fuse(STEP, STEP + np.array([0.0, 0.0, math.radians(1.5)]), MATCH_COV) is not None
    assert trust.fuse(STEP, STEP + np.array([0.0, 0.0, math.radians(10.0)]), MATCH_COV) is None


def test_headings_are_fused_across_the_wrap() -> None:
    trust = _fed(_alternating(40, 0.017, 0.017, 0.45))
    odo = np.array([0.5, 0.0, math.radians(179.9)])
    match = np.array([0.5, 0.0, math.radians(-179.9)])  # 0.2 deg from the odometry, across +-180
    assert innovation(odo, match)[2] == pytest.approx(math.radians(0.2))
    fused = trust.fuse(odo, match, MATCH_COV)
    assert fused is not None
    assert abs(fused[0][2]) > math.radians(179.9)  # between the two, not near 0


def test_heading_only_leaves_the_translation_to_the_match() -> None:
    """The default preset fuses the heading alone (odometry_trust_translation = false)."""
    trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=(2,))
    for dx, dy, dth in _alternating(40, 0.017, 0.017, 0.45):
        trust.add(STEP, STEP + np.array([dx, dy, math.radians(dth)]))
    var = trust.variances(np.diag(MATCH_COV))
    assert var is not None and np.isinf(var[:2]).all() and np.isfinite(var[2])
    match = STEP + np.array([0.03, -0.02, math.radians(0.8)])
    fused = trust.fuse(STEP, match, MATCH_COV)
    assert fused is not None
    pose, cov = fused
    assert pose[0] == match[0] and pose[1] == match[1]
    assert STEP[2] < pose[2] < match[2] and cov[2, 2] < MATCH_COV[2, 2]


def _horizon_fed(centre_deg: float, bias_horizon: int) -> OdometryTrust:
    """40 matches at ``centre_deg`` +- 0.2 deg from the odometry's heading (x, y: +-0.01 m about 0)."""
    trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, bias_horizon=bias_horizon)
    for dx, dy, dth in _alternating(40, 0.01, 0.01, 0.2):
        trust.add(STEP, STEP + np.array([dx, dy, math.radians(centre_deg + dth)]))
    return trust


def test_a_steady_bias_the_median_test_passes_counts_as_accumulated_over_the_horizon() -> None:
    """Matches 0.1 deg off the odometry's heading, +-0.2 deg: within the median test's 3 standard errors (0.18 deg)
    and, as white noise, far better than the match (0.5 deg); counted as a bias over 50 steps it is worse."""
    spread = MAD_TO_SIGMA * math.radians(0.2)
    standard_error = MEDIAN_EFFICIENCY * spread / math.sqrt(40)
    assert math.radians(0.1) < 3.0 * standard_error
    floor = spread**2 * math.sqrt(2.0 / 40)
    plain = _horizon_fed(0.1, 0).variances(np.diag(MATCH_COV))
    assert plain is not None and plain[2] == pytest.approx(floor)
    var = _horizon_fed(0.1, 50).variances(np.diag(MATCH_COV))
    assert var is not None and math.isinf(var[2])
    assert floor + 50 * (math.radians(0.1) ** 2 - standard_error**2) > MATCH_COV[2, 2]
    # 0.07 deg: the accumulated bias is added to the variance, which stays below the match's
    var = _horizon_fed(0.07, 50).variances(np.diag(MATCH_COV))
    assert var is not None
    assert var[2] == pytest.approx(floor + 50 * (math.radians(0.07) ** 2 - standard_error**2))
    assert var[2] < MATCH_COV[2, 2]
    # x and y have a median of 0: no bias is counted there
    assert var[0] == pytest.approx(plain[0]) and var[1] == pytest.approx(plain[1])


def test_a_median_within_its_standard_error_counts_as_no_bias() -> None:
    """The median of white innovations is off 0 by its standard error on average: only the excess counts."""
    standard_error = MEDIAN_EFFICIENCY * 1.0 / math.sqrt(40)
    assert squared_bias(0.0, 1.0, 40) == 0.0
    assert squared_bias(0.9 * standard_error, 1.0, 40) == 0.0
    assert squared_bias(2.0 * standard_error, 1.0, 40) == pytest.approx(3.0 * standard_error**2)
    assert squared_bias(-2.0 * standard_error, 1.0, 40) == pytest.approx(3.0 * standard_error**2)


def test_the_weight_floor_keeps_a_trusted_odometry_from_outweighing_its_match() -> None:
    """Perfect-odometry-like innovations (+-0.2 deg): trusted at the sampling floor, or at the match's own variance
    (ratio 1) or half of it (0.5); what is not trusted stays so; the fused heading is then the plain mean."""
    spread = MAD_TO_SIGMA * math.radians(0.2)
    for ratio, expected in (
        (0.0, spread**2 * math.sqrt(2.0 / 40)),
        (0.5, 0.5 * MATCH_COV[2, 2]),
        (1.0, MATCH_COV[2, 2]),
    ):
        trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, min_variance_ratio=ratio)
        for dx, dy, dth in _alternating(40, 0.01, 0.01, 0.2):
            trust.add(STEP, STEP + np.array([dx, dy, math.radians(dth)]))
        var = trust.variances(np.diag(MATCH_COV))
        assert var is not None and var[2] == pytest.approx(expected)
    match = STEP + np.array([0.0, 0.0, math.radians(0.4)])
    fused = trust.fuse(STEP, match, MATCH_COV)
    assert fused is not None and fused[0][2] == pytest.approx(STEP[2] + math.radians(0.2))
    worse = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, min_variance_ratio=1.0)
    for dx, dy, dth in _alternating(40, 0.03, 0.03, 0.8):
        worse.add(STEP, STEP + np.array([dx, dy, math.radians(dth)]))
    var = worse.variances(np.diag(MATCH_COV))
    assert var is not None and np.isinf(var).all()
