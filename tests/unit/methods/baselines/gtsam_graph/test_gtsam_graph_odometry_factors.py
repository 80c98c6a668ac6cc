"""The odometry as its own between factor, earlier steps judged once the variance is learnt (OdometryFactors)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.methods.baselines.gtsam_graph.graph import PoseGraph
from albot1.methods.baselines.gtsam_graph.odometry_trust import (
    UNTRUSTED_VARIANCE,
    OdometryFactors,
    OdometryTrust,
)

STEP = np.array([0.5, 0.02, math.radians(3.0)])  # one node step of odometry, previous node's frame
MATCH_COV = np.diag([0.02**2, 0.02**2, math.radians(0.5) ** 2])  # the match floor of the default preset


def _factors() -> OdometryFactors:
    """Heading only, as the default preset: 40 steps before anything can be judged (min_history(3) = 40)."""
    return OdometryFactors(OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=(2,)))


#: White, unbiased heading disagreement of 0.3 deg sigma (a fixed sample: its median is 0.3 standard errors from 0).
NOISE_DEG = 0.3 * np.random.default_rng(0).standard_normal(100)


def _match(k: int, outlier_deg: float | None = None) -> np.ndarray:
    """The match of node ``k``: the odometry step turned by the sample's k-th error (or by ``outlier_deg``)."""
    dth = NOISE_DEG[k] if outlier_deg is None else outlier_deg
    return STEP + np.array([0.0, 0.0, math.radians(float(dth))])


def test_the_first_steps_get_their_factors_once_the_variance_is_learnt_then_one_per_step() -> None:
    factors = _factors()
    for key in range(1, 40):
        assert factors.add(key, STEP, _match(key), MATCH_COV) == []
    judged = factors.add(40, STEP, _match(40), MATCH_COV)
    assert [f.key for f in judged] == list(range(1, 41))
    variance = factors.trust.variances(np.diag(MATCH_COV))
    assert variance is not None and math.isfinite(variance[2])
    for f in judged:
        assert np.array_equal(f.step, STEP)
        assert np.array_equal(f.covariance, np.diag([UNTRUSTED_VARIANCE, UNTRUSTED_VARIANCE, variance[2]]))
    later = factors.add(41, STEP, _match(41), MATCH_COV)
    assert [f.key for f in later] == [41]


def test_an_early_step_beyond_the_gate_gets_no_factor_when_it_is_judged() -> None:
    factors = _factors()
    for key in range(1, 41):
        judged = factors.add(key, STEP, _match(key, 10.0 if key == 5 else None), MATCH_COV)
    assert [f.key for f in judged] == [k for k in range(1, 41) if k != 5]


def test_a_biased_odometry_gets_no_factor_and_its_steps_are_not_kept() -> None:
    """Every match 0.5 deg off the odometry (+-0.1 deg): systematic, so never fused, before or after the test."""
    factors = _factors()
    offsets = [STEP + np.array([0.0, 0.0, math.radians(0.5 + (0.1 if k % 2 else -0.1))]) for k in range(1, 42)]
    for key, match in enumerate(offsets, start=1):
        assert factors.add(key, STEP, match, MATCH_COV) == []
    assert factors._pending == []


def test_a_factor_in_the_graph_gives_the_fused_edge() -> None:
    """Match edge + odometry factor in GTSAM: the information-weighted mean a fused edge would have had."""
    factors = _factors()
    for key in range(1, 40):
        factors.add(key, STEP, _match(key), MATCH_COV)
    match = STEP + np.array([0.0, 0.0, math.radians(0.8)])
    judged = factors.add(40, STEP, match, MATCH_COV)
    assert judged[-1].key == 40
    w_match, w_odo = 1.0 / MATCH_COV[2, 2], 1.0 / judged[-1].covariance[2, 2]
    graph = PoseGraph()
    graph.add_node(np.zeros(3))
    graph.add_node(match)
    graph.add_edge(0, 1, match, MATCH_COV)
    graph.add_edge(0, 1, judged[-1].step, judged[-1].covariance)
    graph.update()
    pose = graph.optimise()[1]
    assert pose[2] == pytest.approx((w_match * match[2] + w_odo * STEP[2]) / (w_match + w_odo), abs=1e-9)
    assert pose[:2] == pytest.approx(match[:2], abs=1e-6)
