"""The distinct-alignment check of loop matches (loop_distinct.py): exact outcomes on synthetic worlds."""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.correlative import SearchWindow, correlative_search
from albot1.methods.baselines.gtsam_graph.loop_distinct import distinct_alignment
from albot1.methods.registry import resolve_config

#: The window of the measured variant: +-2 m, the coarse search's steps and angles (0.2 m, +-15 deg by 3 deg).
WINDOW = SearchWindow(half_width_m=2.0, step_m=0.2, half_angle_rad=math.radians(15.0), step_rad=math.radians(3.0))


def random_walls(seed: int = 0, walls: int = 30, extent_m: float = 20.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    parts = []
    for _ in range(walls):
        start = rng.uniform(-extent_m, extent_m, 2)
        direction = rng.uniform(-6.0, 6.0, 2)
        parts.append(start + np.linspace(0.0, 1.0, 80)[:, None] * direction)
    return np.concatenate(parts)


def seen_from(world: np.ndarray, pose: np.ndarray, range_m: float = 10.0) -> np.ndarray:
    local = se2.transform_points(se2.inverse(pose), world)
    return local[np.hypot(local[:, 0], local[:, 1]) < range_m]


def corridor(period_m: float) -> np.ndarray:
    """Two walls 3 m apart with a post every ``period_m``: shifting by one period explains a scan exactly as well."""
    xs = np.arange(-30.0, 30.0, 0.05)
    posts = [np.column_stack([np.full(10, x), np.linspace(-1.5, -1.0, 10)]) for x in np.arange(-30.0, 30.0, period_m)]
    return np.concatenate(
        [np.column_stack([xs, np.full_like(xs, -1.5)]), np.column_stack([xs, np.full_like(xs, 1.5)]), *posts]
    )


def test_the_true_pose_of_a_distinct_scene_passes() -> None:
    world = random_walls()
    truth = np.array([1.0, -2.0, 0.3])
    assert distinct_alignment(world, seen_from(world, truth), truth, WINDOW, 1.0) == ""
    assert distinct_alignment(world, seen_from(world, truth), truth, WINDOW, 0.9) == ""


def test_a_pose_in_a_local_minimum_is_refused_with_the_distance_of_the_better_one() -> None:
    world = random_walls()
    truth = np.array([1.0, -2.0, 0.3])
    # The match's pose 1.6 m off along a grid axis: the grid holds the true pose, which fits better.
    wrong = truth + np.array([1.6, 0.0, 0.0])
    reason = distinct_alignment(world, seen_from(world, truth), wrong, WINDOW, 1.0)
    assert reason == "local minimum (a pose 1.6 m away fits better)"


def test_a_pose_off_by_less_than_the_ambiguity_radius_is_not_a_local_minimum() -> None:
    world = random_walls()
    truth = np.array([1.0, -2.0, 0.3])
    # 0.6 m off: the better pose lies within 1 m, the same basin (ICP's own job), so the check does not object.
    assert distinct_alignment(world, seen_from(world, truth), truth + np.array([0.0, 0.6, 0.0]), WINDOW, 1.0) == ""


def test_a_repeating_corridor_is_refused_only_by_the_ratio_test() -> None:
    world = corridor(1.6)
    truth = np.zeros(3)
    scan = seen_from(world, truth, 8.0)
    found = correlative_search(world, scan, truth, WINDOW)
    # A shift by one period scores as well as the truth; ties go to the pose nearest the guess (the truth).
    assert np.array_equal(found.pose, truth)
    assert found.ambiguity > 0.9
    assert distinct_alignment(world, scan, truth, WINDOW, 1.0) == ""
    assert distinct_alignment(world, scan, truth, WINDOW, 0.9) == f"indistinct ({found.ambiguity:.2f})"


def test_the_shipped_preset_leaves_the_check_off() -> None:
    cfg = resolve_config("gtsam-graph", "default", {})
    assert isinstance(cfg, GtsamGraphConfig)
    assert cfg.loop_distinct_half_width_m == 0.0
    assert cfg.loop_distinct_max_ambiguity == 1.0
