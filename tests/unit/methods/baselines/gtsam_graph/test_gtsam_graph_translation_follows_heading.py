"""The odometry's translation trusted where its heading is (odometry_trust.OdometryTrust, translation_follows_heading).

With perfect odometry the innovations are the matches' own errors; the matches claim the floor (0.02 m) in translation
but are off by 1.5-2.3x that in variance (docs/baselines.md, gtsam-graph, "where the error with perfect odometry comes
from"), so covariance matching puts the excess on the odometry and never trusts its translation. The heading's claim
holds, so the heading's verdict decides instead.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.odometry_trust import MAD_TO_SIGMA, OdometryTrust
from albot1.methods.registry import resolve_config

STEP = np.array([0.5, 0.02, math.radians(3.0)])
MATCH_COV = np.diag([0.02**2, 0.02**2, math.radians(0.5) ** 2])  # the default preset's match floor


def _fed(dxy: float, dth_deg: float, follows: bool, n: int = 50) -> OdometryTrust:
    """Innovations alternating +-dxy (m, both axes) and +-dth_deg about 0: unbiased, spread 1.4826 x the size."""
    trust = OdometryTrust(n, bias_z=3.0, gate_chi2=16.27, translation_follows_heading=follows)
    for k in range(n):
        s = 1.0 if k % 2 else -1.0
        trust.add(STEP, STEP + np.array([s * dxy, s * dxy, s * math.radians(dth_deg)]))
    return trust


def test_a_translation_the_match_claim_cannot_explain_is_trusted_where_the_heading_is() -> None:
    """+-0.03 m against a 0.02 m claim: the old rule gives inf (worse than the match); following the heading, the
    variance the innovations earn (spread^2 - claim), with the heading trusted (+-0.2 deg, below its claim)."""
    spread = MAD_TO_SIGMA * 0.03
    earned = spread**2 - 0.02**2
    assert earned > 0.02**2  # the old rule's verdict: the odometry is the worse of the two
    old = _fed(0.03, 0.2, follows=False).variances(np.diag(MATCH_COV))
    new = _fed(0.03, 0.2, follows=True).variances(np.diag(MATCH_COV))
    assert old is not None and new is not None
    assert np.isinf(old[:2]).all() and np.isfinite(old[2])
    assert new[0] == pytest.approx(earned) and new[1] == pytest.approx(earned)
    assert new[2] == pytest.approx(old[2])


def test_no_translation_is_trusted_where_the_heading_is_not() -> None:
    """+-0.8 deg: the heading is worse than its match, so the translation (however small) gets nothing either."""
    var = _fed(0.005, 0.8, follows=True).variances(np.diag(MATCH_COV))
    assert var is not None and np.isinf(var).all()


def test_a_trusted_translation_is_never_below_the_floor() -> None:
    """+-0.005 m: the earned variance is at its sampling floor, below the claim; the weight floor (1) lifts it."""
    trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, min_variance_ratio=1.0, translation_follows_heading=True)
    for k in range(50):
        s = 1.0 if k % 2 else -1.0
        trust.add(STEP, STEP + np.array([s * 0.005, s * 0.005, s * math.radians(0.2)]))
    var = trust.variances(np.diag(MATCH_COV))
    assert var is not None
    assert var[0] == pytest.approx(0.02**2) and var[1] == pytest.approx(0.02**2)


def test_a_step_is_gated_on_its_heading_alone() -> None:
    """A match 0.5 m off the odometry but agreeing in heading: gated when the translation joins the test, kept when
    the step is judged by its heading (the translation's claim is what cannot be trusted)."""
    match = STEP + np.array([0.5, 0.0, 0.0])
    old = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27)
    new = _fed(0.005, 0.2, follows=True)
    for k in range(50):
        s = 1.0 if k % 2 else -1.0
        old.add(STEP, STEP + np.array([s * 0.005, s * 0.005, s * math.radians(0.2)]))
    assert old.gated_variances(STEP, match, MATCH_COV) is None
    assert new.gated_variances(STEP, match, MATCH_COV) is not None
    turned = STEP + np.array([0.0, 0.0, math.radians(5.0)])
    assert new.gated_variances(STEP, turned, MATCH_COV) is None  # a heading disagreement is still gated


def test_the_setting_is_off_in_the_preset_and_refused_without_the_translation() -> None:
    cfg = resolve_config("gtsam-graph", "default", {})
    assert isinstance(cfg, GtsamGraphConfig)
    assert cfg.odometry_trust_translation_follows_heading is False
    with pytest.raises(ValidationError, match="odometry_trust_translation_follows_heading needs"):
        GtsamGraphConfig.model_validate({**cfg.model_dump(), "odometry_trust_translation_follows_heading": True})
    on = {**cfg.model_dump(), "odometry_trust_translation_follows_heading": True, "odometry_trust_translation": True}
    assert GtsamGraphConfig.model_validate(on).odometry_trust_translation_follows_heading is True
