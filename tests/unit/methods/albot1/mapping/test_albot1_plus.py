"""Albot1+ (preset ``plus``): the pose solver on exact geometry, the odometry learner, and a whole-world bound."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.open import open_sequence
from albot1.geometry import se2
from albot1.geometry.segments import transform_segments
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import OdometryNoise, PlusLocaliser
from albot1.methods.albot1.mapping.screen import screen_measurement
from albot1.methods.albot1.mapping.start_poses import ODOMETRY_TURNS_DEG, start_poses
from albot1.methods.albot1.mapping.view_noise import CHI2_1_MEDIAN
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


def solve(starts, lm_view, lm_map, ok, points, ref, *, prior=(0.0, 0.0, 0.0), info=(0.0, 0.0), overhang=math.inf):
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
        overhang,
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
    # localisation's list of candidate poses gives the same starts, bit for bit, as their array
    listed = start_poses(odometry, (1.1, 2.1, 0.4), [(0.0, 0.0, 0.0), (5.0, 5.0, 1.0)])
    assert listed.flags["C_CONTIGUOUS"] and listed.dtype == np.float64
    np.testing.assert_array_equal(listed, both)
    assert start_poses(odometry, (1.1, 2.1, 0.4), []).shape == (2, 3)


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
    loc = PlusLocaliser(plus_params(degenerate_sd_m=0.0, gate_probability=0.0), KERNELS, 30.0)
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


CORRIDOR = np.array([[-1.0, 0.0, -1.0, 8.0], [1.0, 8.0, 1.0, 0.0]])  # two parallel walls along thesis +y


def corridor_fit(start: tuple[float, float, float]) -> tuple[tuple[float, float, float], np.ndarray]:
    """The scan-only fit in the corridor from ``start``: exact across it, left at the start along it."""
    x, y, phi, info = solve(
        [start], np.empty((0, 4)), np.empty((0, 4)), np.empty((0, 2)), sampled_points(CORRIDOR), CORRIDOR
    )
    return (x, y, phi), info


def test_the_screen_keeps_the_odometrys_component_along_a_corridor() -> None:
    measured, info = corridor_fit((0.1, 0.7, math.radians(2.0)))  # the damped solver left y at the start, 0.7
    predicted = (0.02, 0.25, math.radians(0.5))  # the odometry's prediction
    params = plus_params(degenerate_sd_m=0.05, gate_probability=0.0)
    screened = screen_measurement(measured, info, predicted, (1e-2, 1e-3), params)
    assert screened.degenerate and not screened.rejected and screened.kept == 2
    # Along the corridor (thesis y) the odometry's component exactly; across it and in heading the fit's.
    assert screened.pose[1] == pytest.approx(0.25, abs=1e-12)
    assert screened.pose[0] == pytest.approx(0.0, abs=1e-6) and screened.pose[2] == pytest.approx(0.0, abs=1e-6)
    assert abs(screened.info[1, 1]) < 1e-9 * info[0, 0]  # no information is left along the axis
    assert screened.info[0, 0] == pytest.approx(info[0, 0], rel=1e-9)


def test_the_fused_pose_follows_the_odometry_along_a_corridor_and_the_fit_across_it() -> None:
    # The screen alone: with the ambiguity test on, this view keeps the prediction whole (test_albot1_ambiguity.py).
    params = plus_params(degenerate_sd_m=0.05, gate_probability=0.999, ambiguity_probability=0.0)
    loc = PlusLocaliser(params, KERNELS, 30.0)
    loc.reset(CORRIDOR, (0.0, 0.0, 0.0))
    since = (0.03, 0.4, math.radians(0.2))  # odometry since the update: 3 cm and 0.2 degrees off across
    pose = loc.pose(
        np.array([[0.03, 0.9, math.radians(0.2)]]),  # a start 50 cm ahead along the corridor (e.g. a mismatch)
        np.empty((0, 4)),
        np.empty((0, 4)),
        (np.empty((0, 2), dtype=np.int64), np.empty((0, 2), dtype=np.int64)),
        sampled_points(CORRIDOR),
        since,
    )
    assert pose[1] == pytest.approx(0.4, abs=1e-9)  # along: the odometry's, not the start's 0.9
    assert abs(pose[0]) < 0.005 and abs(pose[2]) < math.radians(0.05)  # across and heading: mostly the walls'
    assert loc.degenerate_views == 1 and loc.gate_rejections == 0


def test_without_the_screen_a_corridor_view_still_fuses_its_unconstrained_direction() -> None:
    """The same view unscreened: the fit's damped y (0.9) leaks into the pose by its rounding-level information."""
    measured, info = corridor_fit((0.03, 0.9, math.radians(0.2)))
    screened = screen_measurement(measured, info, (0.03, 0.4, 0.0), (1e-2, 1e-3), plus_params(gate_probability=0.0))
    assert measured[1] == pytest.approx(0.9, abs=1e-3) and screened.pose[1] == pytest.approx(0.4, abs=1e-12)


def test_the_gate_rejects_a_fit_that_disagrees_with_the_odometry_beyond_their_uncertainty() -> None:
    lm_map = transform_segments(TRUE_POSE, VIEW_SURFACES)
    points = sampled_points(VIEW_SURFACES)
    ok = np.ones((len(VIEW_SURFACES), 2), dtype=bool)
    x, y, phi, info = solve([[0.35, -0.15, 0.05]], VIEW_SURFACES, lm_map, ok, points, lm_map)
    params = plus_params(degenerate_sd_m=0.05, gate_probability=0.999)
    variance = (0.01**2, math.radians(0.5) ** 2)  # the odometry's prediction known to 1 cm and 0.5 degrees
    near = (TRUE_POSE[0] + 0.005, TRUE_POSE[1] - 0.004, TRUE_POSE[2] + math.radians(0.3))
    kept = screen_measurement((x, y, phi), info, near, variance, params)
    assert not kept.rejected and not kept.degenerate and kept.kept == 3
    np.testing.assert_allclose(kept.pose, (x, y, phi), atol=1e-12)  # all directions fixed: the fit unchanged
    # Chi-square(3) at 0.999 is 16.27: a prediction 20 cm off (20 sigma of the odometry) is a wrong association.
    far = (TRUE_POSE[0] + 0.2, TRUE_POSE[1], TRUE_POSE[2])
    rejected = screen_measurement((x, y, phi), info, far, variance, params)
    assert rejected.rejected and rejected.pose == far
    # The squared disagreement in the sum of the stated covariances (prior_m_per_rad = 1: no rescaling).
    d = np.array([x - far[0], y - far[1], phi - far[2]])
    expected = d @ np.linalg.solve(np.linalg.inv(info) + np.diag([variance[0], variance[0], variance[1]]), d)
    assert rejected.mahalanobis == pytest.approx(expected, rel=1e-9) and expected > 16.27
    loc = PlusLocaliser(params, KERNELS, 30.0)
    # After 1 cm of motion the start values of the learnt spread give the prediction ~1 cm: 20 cm is rejected.
    assert loc._fuse((x, y, phi), info, far, 0.01) == far and loc.gate_rejections == 1


def test_the_thesis_presets_leave_the_screen_off() -> None:
    for name in ("default", "thesis", "exact", "literal"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.degenerate_sd_m == 0.0 and config.gate_probability == 0.0
