"""UTM-like coordinates (5e5 / 5e6 m) cost the metrics no precision: the same route at the origin scores the same.

A guard, not a fix: an outsider's check (metric49) measured ATE changing by 1.6e-11 m and the alignment-free
metrics by at most 2e-9 m or deg when both trajectories move 5e6 m away; the tolerances below are the float64
spacing there (9.3e-10 m) times the few roundings each number goes through, far below any printed digit.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.geometry import se2
from albot1.metrics.ate import ate, windowed_ate
from albot1.metrics.drift import drift
from albot1.metrics.rpe import rpe

far = st.floats(-5e6, 5e6, allow_nan=False)
angle = st.floats(-np.pi, np.pi, allow_nan=False)


def route(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A wandering 110-180 m reference and a drifting estimate of it in its own frame (seeded; steps never equal)."""
    rng = np.random.default_rng(seed)
    steps = np.column_stack([rng.uniform(0.3, 0.8, 300), rng.normal(0, 0.02, 300), rng.normal(0, 0.1, 300)])
    ref = se2.integrate_steps(np.zeros(3), steps)
    noisy = steps * [1.01, 1.0, 1.0] + np.column_stack([rng.normal(0, 0.02, (300, 2)), rng.normal(0, 0.01, 300)])
    return se2.integrate_steps(rng.normal(0, 1, 3), noisy), ref


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), x=far, y=far, th=angle, dx=far, dy=far, dth=angle)
def test_far_coordinates_score_as_at_the_origin(
    seed: int, x: float, y: float, th: float, dx: float, dy: float, dth: float
) -> None:
    """Both trajectories moved by one rigid motion up to 5e6 m, the estimate by another too: the same numbers."""
    est, ref = route(seed)
    common = np.array([x, y, th])
    ref_far = se2.compose(common, ref)
    est_far = se2.compose(np.array([dx, dy, dth]), se2.compose(common, est))
    near, moved = ate(est, ref), ate(est_far, ref_far)
    assert moved["rmse_m"] == pytest.approx(near["rmse_m"], abs=1e-7)
    assert moved["rotation"]["rmse_deg"] == pytest.approx(near["rotation"]["rmse_deg"], abs=1e-7)
    assert moved["other_alignments"]["first"]["rmse_m"] == pytest.approx(
        near["other_alignments"]["first"]["rmse_m"], abs=1e-6
    )
    for delta, unit in ((1, "frames"), (10.0, "m")):
        a, b = rpe(est, ref, delta, unit), rpe(est_far, ref_far, delta, unit)  # type: ignore[arg-type]
        assert b["pairs"] == a["pairs"]
        assert b["translation_m"]["rmse"] == pytest.approx(a["translation_m"]["rmse"], abs=1e-7)
    d_near, d_far = drift(est, ref)["at_10m"], drift(est_far, ref_far)["at_10m"]
    assert d_far["pairs"] == d_near["pairs"]
    assert d_far["translation_m"] == pytest.approx(d_near["translation_m"], abs=1e-7)
    w_near, w_far = windowed_ate(est, ref), windowed_ate(est_far, ref_far)
    assert [(w["first_scan"], w["last_scan"]) for w in w_far["per_window"]] == [
        (w["first_scan"], w["last_scan"]) for w in w_near["per_window"]
    ]
    assert w_far["mean_rmse_m"] == pytest.approx(w_near["mean_rmse_m"], abs=1e-7)
