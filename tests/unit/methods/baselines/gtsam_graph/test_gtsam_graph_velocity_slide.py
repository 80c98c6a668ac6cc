"""The velocity guess's slide check (velocity_slide.py): exact outcomes on synthetic geometry."""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.registration import Target
from albot1.methods.baselines.gtsam_graph.velocity_slide import alignment_score, shift_m, slide_refused
from albot1.methods.registry import resolve_config

SIGMA_M = 0.05


def plain_target(points: np.ndarray) -> Target:
    """A target whose normals do not matter here (the score reads distances only)."""
    return Target(points, np.tile([0.0, 1.0], (len(points), 1)))


def corridor() -> np.ndarray:
    """Two featureless walls 3 m apart, a point every 5 cm from -30 to 30 m: no position along x is told apart."""
    xs = np.round(np.arange(-600, 601) * 0.05, 10)
    return np.concatenate([np.column_stack([xs, np.full_like(xs, -1.5)]), np.column_stack([xs, np.full_like(xs, 1.5)])])


def room() -> np.ndarray:
    """A closed 6 x 4 m room with a 1 m pillar: every pose is told apart from one 1 m away."""
    t = np.arange(0.0, 1.0, 0.01)[:, None]
    sides = [((-3, -2), (3, -2)), ((3, -2), (3, 2)), ((3, 2), (-3, 2)), ((-3, 2), (-3, -2)), ((0.5, 0), (1.5, 0))]
    return np.concatenate([np.asarray(a) + t * (np.asarray(b) - np.asarray(a)) for a, b in sides])


def seen_from(world: np.ndarray, pose: np.ndarray, range_m: float) -> np.ndarray:
    local = se2.transform_points(se2.inverse(pose), world)
    return local[np.hypot(local[:, 0], local[:, 1]) < range_m]


def test_the_shift_is_measured_in_the_frame_of_the_odometry_guess() -> None:
    guess = np.array([1.0, 2.0, math.pi / 2])
    assert math.isclose(shift_m(se2.compose(guess, np.array([0.3, 0.4, 0.1])), guess), 0.5)


def test_the_score_is_one_on_the_map_exp_minus_half_one_sigma_off_and_zero_without_points() -> None:
    wall = np.column_stack([np.arange(0.0, 5.0, 0.05), np.zeros(100)])
    target = plain_target(wall)
    assert alignment_score(target, wall, np.zeros(3), SIGMA_M) == 1.0
    assert math.isclose(alignment_score(target, wall, np.array([0.0, SIGMA_M, 0.0]), SIGMA_M), math.exp(-0.5))
    assert alignment_score(target, np.empty((0, 2)), np.zeros(3), SIGMA_M) == 0.0
    assert alignment_score(plain_target(np.empty((0, 2))), wall, np.zeros(3), SIGMA_M) == 0.0


def test_the_translation_gate_refuses_a_velocity_match_beyond_it_and_passes_one_within() -> None:
    target = plain_target(corridor())
    guess = np.array([0.0, 0.0, 0.2])
    far = se2.compose(guess, np.array([0.7, 0.0, 0.0]))
    near = se2.compose(guess, np.array([0.5, 0.0, 0.0]))
    scan = seen_from(corridor(), guess, 8.0)
    assert slide_refused(target, scan, far, guess, guess, 0.6, 0.0, SIGMA_M) == "shift 0.70 m > 0.60 m"
    assert slide_refused(target, scan, near, guess, guess, 0.6, 0.0, SIGMA_M) == ""
    # Off (None, 0): nothing is refused.
    assert slide_refused(target, scan, far, guess, guess, None, 0.0, SIGMA_M) == ""


def test_a_slide_along_a_featureless_corridor_is_refused_by_the_scene_test() -> None:
    world = corridor()
    truth = np.zeros(3)
    scan = seen_from(world, truth, 8.0)
    slid = np.array([1.5, 0.0, 0.0])  # 30 point spacings along the walls: the slid scan lies on the map too
    target = plain_target(world)
    assert alignment_score(target, scan, slid, SIGMA_M) == alignment_score(target, scan, truth, SIGMA_M) == 1.0
    assert slide_refused(target, scan, slid, truth, truth, None, 0.9, SIGMA_M) == "indistinct (1.000 vs 1.000)"


def test_a_velocity_match_the_room_tells_apart_replaces_the_odometry_match() -> None:
    world = room()
    truth = np.array([-1.0, 0.5, 0.1])
    scan = seen_from(world, truth, 10.0)
    target = plain_target(world)
    # The odometry match 1 m off (the odometry was wrong), the velocity match at the truth: the room says which.
    wrong = truth + np.array([1.0, 0.0, 0.0])
    assert alignment_score(target, scan, wrong, SIGMA_M) < 0.9 * alignment_score(target, scan, truth, SIGMA_M)
    assert slide_refused(target, scan, truth, wrong, wrong, None, 0.9, SIGMA_M) == ""
    # ... and the other way round the velocity match is refused: the odometry's pose fits better.
    assert slide_refused(target, scan, wrong, truth, truth, None, 0.9, SIGMA_M).startswith("indistinct (1.000 vs 0.")


def test_the_shipped_preset_has_the_translation_gate_on_and_the_scene_test_off() -> None:
    cfg = resolve_config("gtsam-graph", "default", {})
    assert isinstance(cfg, GtsamGraphConfig)
    assert cfg.track_velocity_max_shift is True
    assert cfg.track_velocity_distinct_ratio == 0.0
