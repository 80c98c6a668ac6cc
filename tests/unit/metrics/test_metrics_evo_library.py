"""Our SE(2) ATE/RPE against evo's library on the same trajectories (an independent implementation)."""

from __future__ import annotations

import copy
import importlib.util

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.metrics.ate import ate
from albot1.metrics.rpe import rpe

# Found, not imported, at collection: the tests import evo (with scipy, ~0.2 s) when they run.
pytestmark = pytest.mark.skipif(importlib.util.find_spec("evo") is None, reason="evo is not installed")


def to_evo(stamps: np.ndarray, poses: np.ndarray) -> object:
    from evo.core import trajectory as evo_trajectory

    half = poses[:, 2] / 2.0
    xyz = np.column_stack([poses[:, 0], poses[:, 1], np.zeros(len(poses))])
    quat_wxyz = np.column_stack([np.cos(half), np.zeros(len(poses)), np.zeros(len(poses)), np.sin(half)])
    return evo_trajectory.PoseTrajectory3D(positions_xyz=xyz, orientations_quat_wxyz=quat_wxyz, timestamps=stamps)


def drifting_pair(seed: int = 7) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    steps = np.column_stack([rng.uniform(0.1, 0.6, 300), rng.normal(0, 0.02, 300), rng.normal(0, 0.08, 300)])
    ref = se2.integrate_steps([1.0, 2.0, 0.3], steps)
    est = se2.integrate_steps(
        [-4.0, 0.5, 2.0], steps + np.array([0.01, 0.0, np.radians(0.3)]) + rng.normal(0, 0.01, steps.shape)
    )
    return np.arange(len(ref)) * 0.1, est, ref


@pytest.mark.parametrize("alignment", ["rigid", "first", "none"])
def test_ate_equals_evo_ape(alignment: str) -> None:
    from evo.core import metrics as evo_metrics

    stamps, est, ref = drifting_pair()
    traj_ref, traj_est = to_evo(stamps, ref), to_evo(stamps, est)
    if alignment == "rigid":
        traj_est.align(traj_ref, correct_scale=False)
    elif alignment == "first":
        traj_est.align_origin(traj_ref)
    ape = evo_metrics.APE(evo_metrics.PoseRelation.translation_part)
    ape.process_data((traj_ref, copy.deepcopy(traj_est)))
    theirs = ape.get_all_statistics()
    ours = ate(est, ref, alignment)  # type: ignore[arg-type]
    for key in ("rmse", "mean", "median", "std", "min", "max"):
        assert ours[f"{key}_m"] == pytest.approx(theirs[key], rel=1e-9, abs=1e-9), key
    rot = evo_metrics.APE(evo_metrics.PoseRelation.rotation_angle_deg)
    rot.process_data((traj_ref, traj_est))
    assert ours["rotation"]["rmse_deg"] == pytest.approx(rot.get_statistic(evo_metrics.StatisticsType.rmse), rel=1e-7)


@pytest.mark.parametrize("delta, unit", [(1, "frames"), (5, "frames"), (1.0, "m"), (10.0, "m")])
def test_rpe_equals_evo_rpe_with_pairs_from_reference(delta: float, unit: str) -> None:
    from evo.core import metrics as evo_metrics

    stamps, est, ref = drifting_pair()
    evo_unit = evo_metrics.Unit.frames if unit == "frames" else evo_metrics.Unit.meters
    ours = rpe(est, ref, delta, unit)  # type: ignore[arg-type]
    for relation, key in (
        (evo_metrics.PoseRelation.translation_part, "translation_m"),
        (evo_metrics.PoseRelation.rotation_angle_deg, "rotation_deg"),
    ):
        metric = evo_metrics.RPE(relation, delta=delta, delta_unit=evo_unit, all_pairs=False, pairs_from_reference=True)
        metric.process_data((to_evo(stamps, ref), to_evo(stamps, est)))
        theirs = metric.get_all_statistics()
        assert ours[key]["n"] == len(metric.error)
        for stat in ("rmse", "mean", "median", "std", "min", "max"):
            assert ours[key][stat] == pytest.approx(theirs[stat], rel=1e-7, abs=1e-9), (key, stat)
