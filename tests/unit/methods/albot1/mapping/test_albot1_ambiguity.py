"""Albot1+'s ambiguity test (``ambiguity_probability``): the view's own cost at the fit and at the odometry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry.se2 import compose_pose
from albot1.geometry.segments import transform_segments
from albot1.methods.albot1.mapping.ambiguity import (
    effective_terms,
    likelihood_ratio,
    measurement_costs,
    threshold,
    view_ambiguity,
)
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import PlusLocaliser
from albot1.methods.albot1.mapping.start_poses import start_poses

KERNELS = MappingKernels(False)
SIGMAS = (0.05, 0.1, 0.05, 2.0, 0.5)  # line, point, scan sigma, Huber (sigmas), gate: the plus preset's
# A room whose walls do not touch (no point is equally near two surfaces): back wall, right and left walls (thesis
# frame, robot facing +y).
ROOM = np.array([[-2.0, 5.0, 2.0, 5.0], [3.0, 4.0, 3.0, 1.0], [-3.0, 1.0, -3.0, 4.0]])
NO_LANDMARKS = (np.empty((0, 4)), np.empty((0, 4)), np.empty((0, 2), dtype=np.bool_))


def wall_points(surfaces: np.ndarray, per_wall: int) -> np.ndarray:
    t = np.linspace(0.0, 1.0, per_wall)
    return np.vstack([np.column_stack([x1 + t * (x2 - x1), y1 + t * (y2 - y1)]) for x1, y1, x2, y2 in surfaces])


def plus_params(**changes: float) -> object:
    return Albot1Config.model_validate({**Albot1Mapper.presets["plus"], **changes}).plus_params()


def test_measurement_costs_counts_every_point_on_its_surface_and_costs_a_sideways_shift_exactly() -> None:
    points = wall_points(ROOM, 11)
    poses = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0]])
    costs, per_surface, matched, terms, independent = measurement_costs(
        poses, *NO_LANDMARKS, points, ROOM, *SIGMAS, math.inf
    )
    assert (terms, independent) == (33, 6)
    assert per_surface.tolist() == [11, 11, 11]
    assert costs[0] == 0.0 and matched == 0.0
    # 1 cm sideways: the 22 side-wall points are 0.2 sigma off (0.02 each), and so is the back wall's right end (now
    # 1 cm beyond its segment); the back wall's other points are still on it.
    assert costs[1] == pytest.approx(23 * 0.5 * 0.2**2, rel=1e-9)


def test_a_point_with_no_surface_in_reach_costs_the_gate_and_is_not_matched() -> None:
    points = np.vstack([wall_points(ROOM[:1], 5), [[0.0, 20.0]]])  # the last point: 15 m beyond the back wall
    costs, per_surface, matched, *_ = measurement_costs(
        np.zeros((1, 3)), *NO_LANDMARKS, points, ROOM, *SIGMAS, math.inf
    )
    assert per_surface.tolist() == [5, 0, 0] and matched == 0.0
    assert costs[0] == pytest.approx(2.0 * (10.0 - 0.5 * 2.0))  # Huber at 10 sigmas (0.5 m / 0.05 m)


def test_effective_terms_count_each_surface_for_its_offset_and_turn_at_most() -> None:
    assert effective_terms(6, np.array([10, 1, 0, 5])) == (22, 11)
    assert effective_terms(0, np.zeros(0, dtype=np.int64)) == (0, 0)


def test_the_likelihood_ratio_in_units_of_the_fits_own_residual_variance() -> None:
    # Residual variance 2 * 10 / (23 - 3) = 1 sigma^2; statistic 2 * 2 / 1 * 10 / 23.
    limit = threshold(0.99)
    assert limit == pytest.approx(11.344867, rel=1e-6) and threshold(0.0) == 0.0
    test = likelihood_ratio(10.0, 12.0, 10.0, 23, 10, limit)
    assert test.statistic == pytest.approx(40.0 / 23.0, rel=1e-12) and test.ambiguous
    # The same cost difference with ten times less scatter refutes the prediction.
    assert not likelihood_ratio(1.0, 3.0, 1.0, 23, 10, limit).ambiguous
    # No more terms than degrees of freedom: nothing can be refuted.
    assert likelihood_ratio(0.0, 100.0, 0.0, 3, 3, limit).ambiguous


def noisy_room(seed: int = 7) -> tuple[np.ndarray, np.ndarray, tuple[float, float, float]]:
    """The room's walls in the map seen from ``pose``, and the view's points with 2 cm noise (seeded)."""
    pose = (0.3, -0.2, math.radians(4.0))
    rng = np.random.default_rng(seed)
    points = wall_points(ROOM, 31) + rng.normal(0.0, 0.02, size=(93, 2))
    return transform_segments(pose, ROOM), np.ascontiguousarray(points), pose


def test_a_prediction_within_the_views_scatter_is_ambiguous_and_one_20_cm_off_is_not() -> None:
    ref, points, pose = noisy_room()
    fitted = (pose[0] + 0.001, pose[1], pose[2])
    limit = threshold(0.99)
    near = view_ambiguity(KERNELS.measurement_costs, fitted, pose, *NO_LANDMARKS, points, ref, SIGMAS, limit)
    assert near.ambiguous and near.statistic < 1.0
    far = (pose[0] + 0.2, pose[1], pose[2])
    refuted = view_ambiguity(KERNELS.measurement_costs, fitted, far, *NO_LANDMARKS, points, ref, SIGMAS, limit)
    assert not refuted.ambiguous and refuted.statistic > 30.0 * refuted.threshold


Pose3 = tuple[float, float, float]


def localise(loc: PlusLocaliser, points: np.ndarray, start: Pose3, since: Pose3) -> Pose3:
    empty_kinds = (np.empty((0, 2), dtype=np.int64), np.empty((0, 2), dtype=np.int64))
    return loc.pose(start_poses(start, None, None), np.empty((0, 4)), np.empty((0, 4)), empty_kinds, points, since)


def test_the_localiser_keeps_the_odometry_where_the_view_does_not_refute_it() -> None:
    ref, points, pose = noisy_room()
    loc = PlusLocaliser(plus_params(ambiguity_probability=0.99), KERNELS, 30.0)
    loc.reset(ref, (0.0, 0.0, 0.0))
    # The odometry since the update (anchored at the origin) predicts the true pose: kept exactly, not the fit.
    assert localise(loc, points, pose, pose) == compose_pose((0.0, 0.0, 0.0), pose)
    assert loc.ambiguous_views == 1 and loc.last_ambiguity is not None and loc.last_ambiguity.ambiguous
    # Odometry 20 cm and 2 degrees off: the view refutes it and the fit (fused) takes the pose back to the walls.
    off = (pose[0] + 0.2, pose[1], pose[2] + math.radians(2.0))
    x, y, phi = localise(loc, points, off, off)
    assert loc.ambiguous_views == 1 and not loc.last_ambiguity.ambiguous
    # (fused with the prediction by their information: within 5 cm of the walls, far from the odometry's 20 cm)
    assert math.hypot(x - pose[0], y - pose[1]) < 0.05 and abs(phi - pose[2]) < math.radians(0.5)


def test_the_test_is_off_unless_asked_for() -> None:
    ref, points, pose = noisy_room()
    loc = PlusLocaliser(plus_params(ambiguity_probability=0.0), KERNELS, 30.0)
    loc.reset(ref, (0.0, 0.0, 0.0))
    assert localise(loc, points, pose, pose) != pose  # the fit is fused: it moves off the prediction
    assert loc.ambiguous_views == 0 and loc.last_ambiguity is None
    for name in ("default", "thesis", "exact", "literal"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.ambiguity_probability == 0.0


CORRIDOR = np.array([[-1.0, 0.0, -1.0, 8.0], [1.0, 8.0, 1.0, 0.0]])  # two parallel walls along thesis +y


def test_a_corridor_fit_worse_than_the_prediction_keeps_the_prediction_in_every_direction() -> None:
    """The test is joint: a fit started 50 cm ahead along the corridor explains the walls' far ends worse (points
    beyond them cost the gate) than the odometry's prediction, so the prediction is kept whole, its 3 cm across too."""
    loc = PlusLocaliser(plus_params(ambiguity_probability=0.99), KERNELS, 30.0)
    loc.reset(CORRIDOR, (0.0, 0.0, 0.0))
    since = (0.03, 0.4, math.radians(0.2))
    points = wall_points(CORRIDOR, 81)
    empty_kinds = (np.empty((0, 2), dtype=np.int64), np.empty((0, 2), dtype=np.int64))
    start = np.array([[0.03, 0.9, math.radians(0.2)]])
    pose = loc.pose(start, np.empty((0, 4)), np.empty((0, 4)), empty_kinds, points, since)
    assert pose == compose_pose((0.0, 0.0, 0.0), since)
    assert loc.last_ambiguity is not None and loc.last_ambiguity.statistic == 0.0 and loc.ambiguous_views == 1
