"""ATE and SE(2) alignment on trajectories with exact answers."""

from __future__ import annotations

import re

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.metrics.alignment import align, rigid_transform
from albot1.metrics.ate import ate
from albot1.metrics.errors import MetricsError


def line(n: int = 11, step: float = 1.0) -> np.ndarray:
    return np.column_stack([np.arange(n) * step, np.zeros(n), np.zeros(n)])


def test_constant_offset_is_removed_by_alignment_but_not_by_none() -> None:
    ref = line()
    est = ref + np.array([0.3, 0.4, 0.0])
    assert ate(est, ref, "none")["rmse_m"] == pytest.approx(0.5)
    assert ate(est, ref, "none")["max_m"] == pytest.approx(0.5)
    assert ate(est, ref, "first")["rmse_m"] == pytest.approx(0.0, abs=1e-12)
    assert ate(est, ref, "rigid")["rmse_m"] == pytest.approx(0.0, abs=1e-12)


def test_linear_lateral_drift_gives_the_known_ate_with_first_pose_alignment() -> None:
    ref = line()
    est = ref.copy()
    est[:, 1] = 0.1 * np.arange(11)  # 0.1 m sideways per metre, heading unchanged
    block = ate(est, ref, "first")
    assert block["mean_m"] == pytest.approx(0.5)
    assert block["max_m"] == pytest.approx(1.0)
    assert block["rmse_m"] == pytest.approx(0.1 * np.sqrt(35.0))  # sqrt(mean(0.01 i^2)), i = 0..10
    assert block["alignment"] == "first"
    assert block["n"] == 11


def test_rigid_alignment_recovers_a_known_motion_exactly() -> None:
    ref = np.column_stack([np.cos(np.linspace(0, 3, 30)) * 5, np.sin(np.linspace(0, 3, 30)) * 3, np.linspace(0, 1, 30)])
    motion = np.array([2.0, -1.0, 0.7])
    est = se2.compose(se2.inverse(motion), ref)  # est in a frame rotated and moved by inv(motion)
    transform = rigid_transform(est, ref)
    np.testing.assert_allclose(transform, motion, atol=1e-12)
    aligned, _ = align(est, ref, "rigid")
    np.testing.assert_allclose(aligned[:, :2], ref[:, :2], atol=1e-12)
    block = ate(est, ref, "rigid")
    assert block["rmse_m"] == pytest.approx(0.0, abs=1e-12)
    assert block["alignment_transform"]["theta_deg"] == pytest.approx(np.degrees(0.7))


def test_rigid_alignment_minimises_rmse_compared_with_perturbed_transforms() -> None:
    rng = np.random.default_rng(3)
    ref = np.column_stack([rng.normal(size=(50, 2)) * 4, rng.normal(size=50)])
    est = ref + np.column_stack([rng.normal(size=(50, 2)) * 0.3, np.zeros(50)])
    best = ate(est, ref, "rigid")["rmse_m"]
    t = rigid_transform(est, ref)
    for delta in ([0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.001], [0, 0, -0.001]):
        moved = se2.compose(t + np.array(delta), est)
        assert np.sqrt(np.mean(np.sum((moved[:, :2] - ref[:, :2]) ** 2, axis=1))) > best


def test_heading_error_is_reported_in_degrees() -> None:
    ref = line()
    est = ref.copy()
    est[:, 2] = np.radians(2.0)
    assert ate(est, ref, "none")["rotation"]["mean_deg"] == pytest.approx(2.0)


@pytest.mark.parametrize(
    "est, ref, needle",
    [
        (np.zeros((3, 3)), np.zeros((4, 3)), "3 poses and the reference 4"),
        (np.zeros((3, 2)), np.zeros((3, 3)), "expected the estimate as (N, 3)"),
        (np.array([[0, 0, 0], [np.nan, 0, 0]]), np.zeros((2, 3)), "non-finite pose at scan 1"),
    ],
)
def test_bad_inputs_raise_metrics_error_naming_the_problem(est: np.ndarray, ref: np.ndarray, needle: str) -> None:
    with pytest.raises(MetricsError, match=re.escape(needle)):
        ate(est, ref)


def test_unknown_alignment_is_rejected() -> None:
    with pytest.raises(MetricsError, match="unknown alignment 'scale'"):
        ate(line(), line(), "scale")  # type: ignore[arg-type]


@pytest.mark.parametrize("n", [1, 2, 7])
def test_a_robot_turning_on_the_spot_takes_the_rotation_from_the_headings(n: int) -> None:
    """All positions equal: every rotation fits them; a perfect estimate in a frame turned by 1 rad is perfect.

    Old code: the rotation kept at 0, so the heading error was the frames' angle, 57.2958 deg, for a perfect run.
    """
    ref = np.column_stack([np.full(n, 3.0), np.full(n, -2.0), se2.wrap(1.0 + 0.4 * np.arange(n))])
    est = se2.compose([5.0, 1.0, -1.0], ref)  # the same motion seen from another frame
    assert np.degrees(rigid_transform(est, ref)[2]) == pytest.approx(np.degrees(1.0), abs=1e-9)
    if n == 1:  # one pose: the alignment fits it, so its ATE (0 by construction) is refused (test_runs_one_scan.py)
        with pytest.raises(MetricsError, match="one pose"):
            ate(est, ref, "rigid")
        return
    block = ate(est, ref, "rigid")
    assert block["rmse_m"] == pytest.approx(0.0, abs=1e-12)
    assert block["rotation"]["max_deg"] == pytest.approx(0.0, abs=1e-9)
    assert block["alignment_transform"]["theta_deg"] == pytest.approx(np.degrees(1.0), abs=1e-9)


def test_a_straight_corridor_determines_the_rotation_in_the_plane() -> None:
    """Collinear positions (evo's 3-D Umeyama refuses them) fix a planar rotation: a known motion is recovered."""
    ref = np.column_stack([np.linspace(0.0, 20.0, 30), np.zeros(30), np.zeros(30)])
    est = se2.compose([-4.0, 7.0, 2.5], ref)
    _, transform = align(est, ref, "rigid")
    assert transform == pytest.approx(se2.inverse([-4.0, 7.0, 2.5]), abs=1e-12)


def test_n_to_align_beyond_the_pairs_is_refused_rather_than_named_but_not_used() -> None:
    """Old code aligned on the 5 pairs there are and wrote ``n_to_align: 1000`` into the block."""
    ref = np.column_stack([np.arange(5.0), np.zeros(5), np.zeros(5)])
    with pytest.raises(MetricsError) as caught:
        ate(ref, ref, "rigid", n_to_align=1000)
    assert str(caught.value) == "n_to_align=1000: the trajectories have 5 pose pairs; expected at most 5"
    assert ate(ref, ref, "rigid", n_to_align=5)["alignment_transform"]["n_to_align"] == 5
