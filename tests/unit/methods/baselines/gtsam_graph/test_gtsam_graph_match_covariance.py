"""A sequential match's covariance shaped by ICP's information (match_covariance, ``match_covariance_shaped``).

ICP's own covariance is millimetres, so every match states the isotropic floor (0.02 m); with perfect odometry the
matches' errors are about the floor along their best-constrained axis and 1.6x it along the weak one
(docs/baselines.md, gtsam-graph, "where the error with perfect odometry comes from"). The shaped covariance keeps
the floor's scale and the information's shape, in the parent frame; the graph re-expresses it in GTSAM's tangent frame.
"""

from __future__ import annotations

import math
from collections import defaultdict

import gtsam
import numpy as np

from albot1.methods.baselines.gtsam_graph.backend import BackEnd
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.frontend import FrontEnd
from albot1.methods.baselines.gtsam_graph.graph import body_frame_covariance
from albot1.methods.baselines.gtsam_graph.match_covariance import floor_covariance, shaped_covariance
from albot1.methods.baselines.gtsam_graph.registration import Registration
from albot1.methods.registry import resolve_config

FLOOR = np.diag([0.02**2, 0.02**2, math.radians(0.5) ** 2])
PRIOR = np.diag([0.1**-2, 0.1**-2, math.radians(5.0) ** -2])


def _corridor(strong: float, weak: float, theta: float = 4.0e5) -> np.ndarray:
    """ICP information of a scan that constrains y ``strong``, x ``weak`` and the heading ``theta`` (no coupling)."""
    return np.diag([weak, strong, theta])


def test_the_best_axis_keeps_the_floor_and_a_weaker_one_grows_by_the_eigenvalue_ratio() -> None:
    cov = shaped_covariance(_corridor(4.0e5, 4.0e4), PRIOR, FLOOR)
    floor_info = 0.02**-2
    # the floor, with the prior in information
    assert math.isclose(cov[1, 1], 1.0 / (floor_info + 0.1**-2), rel_tol=1e-9)
    assert math.isclose(cov[0, 0], 1.0 / (floor_info / 10.0 + 0.1**-2), rel_tol=1e-9)  # 10x weaker: 10x the variance
    assert cov[0, 1] == 0.0 and cov[0, 2] == 0.0 and cov[1, 2] == 0.0
    # the heading as the floor's formula states it
    assert math.isclose(cov[2, 2], floor_covariance(_corridor(4.0e5, 4.0e4), PRIOR, FLOOR)[2, 2], rel_tol=1e-12)


def test_a_well_conditioned_match_states_about_the_floor_and_a_bare_corridor_the_prior() -> None:
    round_room = shaped_covariance(_corridor(4.0e5, 4.0e5), PRIOR, FLOOR)
    old = floor_covariance(_corridor(4.0e5, 4.0e5), PRIOR, FLOOR)
    assert np.allclose(np.sqrt(np.diag(round_room)[:2]), np.sqrt(np.diag(old)[:2]), rtol=0.03)
    bare = shaped_covariance(_corridor(4.0e5, 0.0), PRIOR, FLOOR)
    assert math.isclose(bare[0, 0], 0.1**2, rel_tol=1e-9)  # no knowledge along x: the odometry prior's variance
    nothing = shaped_covariance(np.zeros((3, 3)), PRIOR, FLOOR)
    assert np.allclose(np.diag(nothing)[:2], [0.1**2, 0.1**2])


def test_translation_knowledge_borrowed_from_the_heading_does_not_count() -> None:
    # x is observed only together with theta (a lever arm): its marginal information is what the Schur complement
    # leaves, so it comes out weaker than the raw diagonal says
    info = np.array([[4.0e5, 0.0, 3.9e5], [0.0, 4.0e5, 0.0], [3.9e5, 0.0, 4.0e5]])
    cov = shaped_covariance(info, PRIOR, FLOOR)
    marginal_x = 4.0e5 - 3.9e5**2 / 4.0e5
    assert math.isclose(cov[0, 0], 1.0 / (0.02**-2 * marginal_x / 4.0e5 + 0.1**-2), rel_tol=1e-9)
    assert cov[0, 0] > 5.0 * cov[1, 1]


def test_the_graph_whitens_a_slip_along_the_parents_weak_axis_by_the_weak_sigma() -> None:
    # a match weak along the parent's x; the child turned 90 deg: once the graph has re-expressed the parent-frame
    # covariance (graph.body_frame_covariance), a slip of the child along the parent's x is whitened by the weak
    # sigma and one along the parent's y by the strong one
    cov = shaped_covariance(_corridor(4.0e5, 4.0e3), PRIOR, FLOOR)
    heading = math.pi / 2
    measured = gtsam.Pose2(1.0, 0.0, heading)
    noise = gtsam.noiseModel.Gaussian.Covariance(body_frame_covariance(np.array([1.0, 0.0, heading]), cov))
    factor = gtsam.BetweenFactorPose2(0, 1, measured, noise)
    for axis, sigma2 in ((0, cov[0, 0]), (1, cov[1, 1])):
        slip = np.zeros(2)
        slip[axis] = 0.01
        values = gtsam.Values()
        values.insert(0, gtsam.Pose2(0.0, 0.0, 0.0))
        values.insert(1, gtsam.Pose2(1.0 + slip[0], slip[1], heading))
        assert math.isclose(2.0 * factor.error(values), 0.01**2 / sigma2, rel_tol=1e-6)
    assert cov[0, 0] > 5.0 * cov[1, 1]


def test_the_setting_is_off_in_the_preset() -> None:
    cfg = resolve_config("gtsam-graph", "default", {})
    assert isinstance(cfg, GtsamGraphConfig)
    assert cfg.match_covariance_shaped is False


def test_the_front_end_states_the_shaped_covariance_and_the_floor_when_off() -> None:
    info = _corridor(4.0e5, 4.0e3)
    reg = Registration(
        pose=np.array([0.5, 0.0, math.pi / 2]),
        converged=True,
        iterations=5,
        fitness=0.9,
        rmse_m=0.02,
        inliers=300,
        information=info,
    )
    base = resolve_config("gtsam-graph", "default", {})
    assert isinstance(base, GtsamGraphConfig)
    for shaped in (True, False):
        cfg = GtsamGraphConfig.model_validate({**base.model_dump(), "match_covariance_shaped": shaped})
        counters: defaultdict[str, int] = defaultdict(int)
        front = FrontEnd(cfg, BackEnd(cfg, counters), counters)
        relative, covariance = front.sequential_edge(reg.pose, np.zeros((0, 2)), 7, reg, odometry_step=None)
        assert np.array_equal(relative, reg.pose)
        floor, prior = cfg.match_floor(), np.diag(np.diag(PRIOR))
        if shaped:
            assert np.array_equal(covariance, shaped_covariance(info, prior, floor))
            assert covariance[0, 0] > 5.0 * covariance[1, 1]  # weak along x, in the parent's frame
        else:
            assert np.array_equal(covariance, np.linalg.inv(info + prior) + floor)
