"""Albot1+ (preset ``plus``): the pose solver on exact geometry, the odometry learner, and a whole-world bound."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.open import open_sequence
from albot1.geometry import se2
from albot1.geometry.segments import transform_segments
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.kernels import MappingKernels
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import (
    CHI2_1_MEDIAN,
    ODOMETRY_TURNS_DEG,
    OdometryNoise,
    PlusLocaliser,
    start_poses,
)
from albot1.methods.albot1.perception.endpoints import CORNER, UNSTABLE
from albot1.metrics.ate import ate

KERNELS = MappingKernels(False)  # the plain functions: exactness, not speed, is tested here
TRUE_POSE = (0.3, -0.2, math.radians(4.0))  # the view's pose in the map (thesis frame)

# A room seen from the view (thesis frame, robot facing +y): a back wall, two side walls and a box.
VIEW_SURFACES = np.array(
    [
        [-3.0, 5.0, 3.0, 5.0],
        [3.0, 5.0, 3.0, 0.5],
        [-3.0, 0.5, -3.0, 5.0],
        [-0.5, 2.0, 0.5, 2.0],
    ]
)


def solve(starts, lm_view, lm_map, ok, points, ref, *, prior=(0.0, 0.0, 0.0), info=(0.0, 0.0)):
    return KERNELS.refine_pose(
        np.ascontiguousarray(starts, dtype=float),
        np.ascontiguousarray(lm_view, dtype=float).reshape(-1, 4),
        np.ascontiguousarray(lm_map, dtype=float).reshape(-1, 4),
        np.ascontiguousarray(ok, dtype=np.bool_).reshape(-1, 2),
        np.ascontiguousarray(points, dtype=float).reshape(-1, 2),
        np.ascontiguousarray(ref, dtype=float).reshape(-1, 4),
        *prior,
        *info,
        0.05,
        0.1,
        0.05,
        2.0,
        0.5,
        20,
    )


def sampled_points(surfaces: np.ndarray, step: float = 0.1) -> np.ndarray:
    out = []
    for x1, y1, x2, y2 in surfaces:
        n = max(2, int(math.hypot(x2 - x1, y2 - y1) / step))
        t = np.linspace(0.0, 1.0, n)
        out.append(np.column_stack([x1 + t * (x2 - x1), y1 + t * (y2 - y1)]))
    return np.vstack(out)


def test_every_landmark_and_the_scan_recover_the_exact_pose() -> None:
    lm_map = transform_segments(TRUE_POSE, VIEW_SURFACES)
    points = sampled_points(VIEW_SURFACES)
    ok = np.ones((len(VIEW_SURFACES), 2), dtype=bool)
    start = [[0.45, -0.05, math.radians(1.0)]]  # 21 cm and 3 degrees off
    x, y, phi, info = solve(start, VIEW_SURFACES, lm_map, ok, points, lm_map)
    np.testing.assert_allclose([x, y, phi], TRUE_POSE, atol=1e-9)
    assert np.all(np.linalg.eigvalsh(info) > 1000.0)  # every direction fixed


def test_point_to_line_terms_alone_recover_the_pose_from_non_parallel_walls() -> None:
    lm_map = transform_segments(TRUE_POSE, VIEW_SURFACES)
    no_points = np.zeros((len(VIEW_SURFACES), 2), dtype=bool)  # no endpoint is stable
    x, y, phi, _ = solve([[0.4, -0.1, 0.05]], VIEW_SURFACES, lm_map, no_points, np.empty((0, 2)), np.empty((0, 4)))
    np.testing.assert_allclose([x, y, phi], TRUE_POSE, atol=1e-9)


def test_a_corridor_fixes_the_lateral_position_and_heading_and_keeps_the_start_along_it() -> None:
    walls = np.array([[-1.0, 0.0, -1.0, 8.0], [1.0, 8.0, 1.0, 0.0]])  # two parallel walls along thesis +y
    pose = (0.0, 0.0, 0.0)
    points = sampled_points(walls)
    start = [[0.1, 0.7, math.radians(2.0)]]  # lateral 10 cm, along 70 cm, heading 2 degrees off
    x, y, phi, info = solve(start, np.empty((0, 4)), np.empty((0, 4)), np.empty((0, 2)), points, walls)
    assert x == pytest.approx(pose[0], abs=1e-6) and phi == pytest.approx(pose[2], abs=1e-6)
    assert y == pytest.approx(0.7, abs=1e-3)  # nothing fixes the position along the walls: it stays at the start
    assert info[1, 1] < 1e-6 * info[0, 0]  # and the information says so


def test_a_stable_endpoint_fixes_the_position_along_a_corridor() -> None:
    walls = np.array([[-1.0, 0.0, -1.0, 8.0], [1.0, 8.0, 1.0, 0.0]])
    door_jamb = np.array([[-1.0, 3.0, -1.0, 5.0]])  # a landmark on the left wall, its P1 a corner at y = 3
    ok = np.array([[True, False]])
    shifted = door_jamb + np.array([0.0, -0.4, 0.0, -0.4])  # seen 40 cm further back: the robot is 40 cm ahead
    x, y, phi, _ = solve([[0.0, 0.0, 0.0]], shifted, door_jamb, ok, sampled_points(walls), walls)
    np.testing.assert_allclose([x, y, phi], [0.0, 0.4, 0.0], atol=1e-6)


def test_the_cheapest_start_is_kept() -> None:
    lm_map = transform_segments(TRUE_POSE, VIEW_SURFACES)
    points = sampled_points(VIEW_SURFACES)
    ok = np.ones((len(VIEW_SURFACES), 2), dtype=bool)
    wrong = [1.5, 1.0, math.radians(35.0)]  # e.g. a mismatched landmark's candidate
    x, y, phi, _ = solve([wrong, [0.35, -0.15, 0.05]], VIEW_SURFACES, lm_map, ok, points, lm_map)
    np.testing.assert_allclose([x, y, phi], TRUE_POSE, atol=1e-9)


def test_a_prior_pulls_by_its_information() -> None:
    walls = np.array([[-1.0, 0.0, -1.0, 8.0], [1.0, 8.0, 1.0, 0.0]])
    _, y, _, _ = solve(
        [[0.0, 0.0, 0.0]],
        np.empty((0, 4)),
        np.empty((0, 4)),
        np.empty((0, 2)),
        sampled_points(walls),
        walls,
        prior=(0.0, 1.0, 0.0),
        info=(1e4, 1e4),
    )
    # Along the corridor only the prior speaks (the damping slows the steps but does not move the solution).
    assert y == pytest.approx(1.0, abs=1e-6)


def test_start_poses() -> None:
    odometry = (1.0, 2.0, 0.5)
    alone = start_poses(odometry, None, None)
    assert alone.shape == (len(ODOMETRY_TURNS_DEG), 3) and alone.flags["C_CONTIGUOUS"]
    np.testing.assert_allclose(alone[:, 2], 0.5 + np.radians(ODOMETRY_TURNS_DEG))
    both = start_poses(odometry, (1.1, 2.1, 0.4), np.array([[0.0, 0.0, 0.0], [5.0, 5.0, 1.0]]))
    np.testing.assert_allclose(both, [[1.1, 2.1, 0.4], [1.0, 2.0, 0.5], [0.0, 0.0, 0.0], [5.0, 5.0, 1.0]])


def plus_params(**changes):
    base = Albot1Config.model_validate({**Albot1Mapper.presets["plus"], **changes})
    return base.plus_params()


def test_the_odometry_learner_finds_the_random_walk_rate() -> None:
    """Disagreements drawn as N(0, q s): the learnt q converges to the true one (the median is robust)."""
    rng = np.random.default_rng(4)
    noise = OdometryNoise(plus_params(prior_learning_rate=0.01))
    true_q = (0.03**2, math.radians(1.5) ** 2)
    for _ in range(6000):
        s = float(rng.uniform(0.1, 1.5))
        noise.learn(true_q[0] * s * rng.standard_normal() ** 2, true_q[1] * s * rng.standard_normal() ** 2, s)
    assert noise.q[0] == pytest.approx(true_q[0], rel=0.1)
    assert noise.q[1] == pytest.approx(true_q[1], rel=0.1)
    # One in ten views mismatched by a metre and 30 degrees moves the median estimate only a little.
    for k in range(3000):
        s = float(rng.uniform(0.1, 1.5))
        bad = k % 10 == 0
        noise.learn(
            1.0 if bad else true_q[0] * s * rng.standard_normal() ** 2,
            math.radians(30.0) ** 2 if bad else true_q[1] * s * rng.standard_normal() ** 2,
            s,
        )
    assert true_q[0] < noise.q[0] < 1.5 * true_q[0]
    assert CHI2_1_MEDIAN == pytest.approx(0.4549364, abs=1e-7)


def test_fusion_weighs_the_measurement_and_the_prediction_by_their_information() -> None:
    loc = PlusLocaliser(plus_params(), KERNELS, 30.0)
    predicted = (1.0, 0.0, 0.0)
    measured = (1.2, 0.1, math.radians(2.0))
    motion = 0.5
    v_xy, v_phi = loc.noise.prior_variance(motion)
    info = np.diag([1.0 / v_xy, 0.0, 3.0 / v_phi])  # y unknown; heading known three times better than predicted
    x, y, phi = loc._fuse(measured, info, predicted, motion)
    assert x == pytest.approx(1.1) and y == pytest.approx(0.0)
    assert phi == pytest.approx(0.75 * math.radians(2.0))


def test_plus_with_perfect_odometry_stays_within_5_cm_on_the_10_degree_world() -> None:
    """Bound: ATE RMSE at most 5 cm over the 79 m loop of 190 views (measured 1.8 cm); thesis: 0.44 m."""
    sequence = open_sequence("synthetic-office-startstop-10deg?odometry=reference")
    mapper = Albot1Mapper(Albot1Config.model_validate(Albot1Mapper.presets["plus"]))
    reference = []
    for frame in sequence.frames():
        mapper.process(frame)
        reference.append(frame.reference)
    out = mapper.finish()
    assert ate(out.poses, np.asarray(reference))["rmse_m"] <= 0.05
    end_gap = se2.between(out.poses[0], out.poses[-1])
    assert math.hypot(end_gap[0], end_gap[1]) <= 0.15  # the route is closed: it ends where it started


def test_a_view_with_an_unstable_end_gives_no_point_term() -> None:
    loc = PlusLocaliser(plus_params(), KERNELS, 30.0)
    lm = VIEW_SURFACES[:1]
    kinds = (np.array([[CORNER, UNSTABLE]]), np.array([[CORNER, CORNER]]))
    loc.reset(transform_segments(TRUE_POSE, VIEW_SURFACES), TRUE_POSE)
    # Only P1 is stable in both: the solver is still exact (the scan points fix the rest).
    pose = loc.pose(
        start_poses(TRUE_POSE, None, None),
        lm,
        transform_segments(TRUE_POSE, lm),
        kinds,
        sampled_points(VIEW_SURFACES),
        (0.0, 0.0, 0.0),
    )
    np.testing.assert_allclose(pose, TRUE_POSE, atol=1e-6)
