"""Aligned and relative metrics do not change when both trajectories move rigidly together."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.model import Relations
from albot1.geometry import se2
from albot1.metrics.ate import ate
from albot1.metrics.loop_gap import route_gap
from albot1.metrics.orientation import orientation_table
from albot1.metrics.relations import relation_metric
from albot1.metrics.rpe import rpe

coord = st.floats(-50, 50, allow_nan=False)
angle = st.floats(-np.pi, np.pi, allow_nan=False)


def trajectories(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A wandering reference and a noisy, drifting estimate of it (seeded)."""
    rng = np.random.default_rng(seed)
    steps = np.column_stack([rng.uniform(0.2, 1.0, 60), rng.normal(0, 0.05, 60), rng.normal(0, 0.2, 60)])
    ref = se2.integrate_steps(np.zeros(3), steps)
    noisy = steps + np.column_stack([rng.normal(0, 0.05, 60), rng.normal(0, 0.05, 60), rng.normal(0, 0.02, 60)])
    est = se2.integrate_steps(rng.normal(0, 1, 3), noisy)
    return est, ref


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), x=coord, y=coord, th=angle, x2=coord, y2=coord, th2=angle)
def test_metrics_are_invariant_to_moving_both_trajectories(
    seed: int, x: float, y: float, th: float, x2: float, y2: float, th2: float
) -> None:
    est, ref = trajectories(seed)
    g_ref, g_est = np.array([x, y, th]), np.array([x2, y2, th2])
    ref2, est2 = se2.compose(g_ref, ref), se2.compose(g_est, est)
    # Rigid alignment absorbs any motion of the estimate and any common motion.
    assert ate(est2, ref2, "rigid")["rmse_m"] == pytest.approx(ate(est, ref, "rigid")["rmse_m"], abs=1e-8)
    assert ate(est2, ref2, "first")["max_m"] == pytest.approx(ate(est, ref, "first")["max_m"], abs=1e-8)
    assert rpe(est2, ref2, 3, "frames")["translation_m"]["rmse"] == pytest.approx(
        rpe(est, ref, 3, "frames")["translation_m"]["rmse"], abs=1e-9
    )
    assert route_gap(est2, ref2)["gap_m"] == pytest.approx(route_gap(est, ref)["gap_m"], abs=1e-9)
    a, b = orientation_table(est2, ref2, every_m=5.0), orientation_table(est, ref, every_m=5.0)
    assert a["bearing_abs_error_max_deg"] == pytest.approx(b["bearing_abs_error_max_deg"], abs=1e-7)
    stamps = np.arange(len(ref)) * 1.0
    rel = Relations(t1=stamps[:-5], t2=stamps[5:], poses=se2.between(ref[:-5], ref[5:]))
    assert relation_metric(stamps, est2, rel)["translation_m"]["mean"] == pytest.approx(
        relation_metric(stamps, est, rel)["translation_m"]["mean"], abs=1e-9
    )


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_rigid_alignment_is_never_worse_than_first_pose_alignment(seed: int) -> None:
    est, ref = trajectories(seed)
    assert ate(est, ref, "rigid")["rmse_m"] <= ate(est, ref, "first")["rmse_m"] + 1e-12
