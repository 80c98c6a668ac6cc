"""Correlative searches: the branch-and-bound global match against an exhaustive search and ambiguous worlds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph import correlative
from albot1.methods.baselines.gtsam_graph.correlative import (
    GlobalWindow,
    _pooled_fields,
    _pose_scores,
    _sum_at,
    _zero_border,
    branch_and_bound_search,
    likelihood_field,
)


def random_walls(seed: int = 0, walls: int = 30, extent_m: float = 30.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    parts = []
    for _ in range(walls):
        start = rng.uniform(-extent_m, extent_m, 2)
        direction = rng.uniform(-8.0, 8.0, 2)
        parts.append(start + np.linspace(0.0, 1.0, 80)[:, None] * direction)
    return np.concatenate(parts)


def seen_from(world: np.ndarray, pose: np.ndarray, range_m: float = 15.0) -> np.ndarray:
    local = se2.transform_points(se2.inverse(pose), world)
    return local[np.hypot(local[:, 0], local[:, 1]) < range_m]


def test_finds_a_pose_metres_and_degrees_from_the_guess() -> None:
    world = random_walls()
    truth = np.array([3.0, -2.0, 0.3])
    guess = truth + np.array([17.3, -11.9, math.radians(-21.0)])
    found = branch_and_bound_search(world, seen_from(world, truth), guess, GlobalWindow(half_width_m=25.0))
    assert np.hypot(*(found.pose[:2] - truth[:2])) < 0.25
    assert abs(se2.wrap(found.pose[2] - truth[2])) < math.radians(1.0)
    assert found.score > 0.9
    assert found.ambiguity < 0.9


def test_best_pose_equals_the_exhaustive_search_of_the_same_grid() -> None:
    world = random_walls(seed=3)
    truth = np.array([1.0, 4.0, -0.2])
    source = seen_from(world, truth)[::7]
    guess = truth + np.array([2.1, -1.7, math.radians(4.0)])
    window = GlobalWindow(
        half_width_m=3.2, half_angle_rad=math.radians(5.0), step_rad=math.radians(1.0), max_points=1000
    )
    found = branch_and_bound_search(world, source, guess, window)
    # Exhaustive: the same field, every translation cell and rotation of the window.
    field, lo = likelihood_field(world, window.cell_m, window.sigma_m)
    n = int(math.ceil(window.half_width_m / (2**window.levels * window.cell_m))) * 2**window.levels
    best = -1.0
    for theta in guess[2] + np.arange(-5, 6) * window.step_rad:
        c, s = math.cos(theta), math.sin(theta)
        cells = np.floor((source @ np.array([[c, s], [-s, c]]) + guess[:2] - lo) / window.cell_m).astype(int)
        for dx in range(-n, n):
            for dy in range(-n, n):
                idx = cells + (dx, dy)
                ok = (idx >= 0).all(axis=1) & (idx < field.shape).all(axis=1)
                best = max(best, float(field[idx[ok, 0], idx[ok, 1]].sum()))
    assert math.isclose(found.score * len(source), best, rel_tol=1e-9)


def test_a_repeating_corridor_is_ambiguous() -> None:
    # Two long walls with a post every 4 m: shifting by one period explains the scan as well.
    xs = np.arange(-40.0, 40.0, 0.05)
    posts = np.concatenate([np.column_stack([np.full(10, x), np.linspace(-1.5, -1.0, 10)]) for x in range(-40, 40, 4)])
    world = np.concatenate(
        [np.column_stack([xs, np.full_like(xs, -1.5)]), np.column_stack([xs, np.full_like(xs, 1.5)]), posts]
    )
    truth = np.array([0.0, 0.0, 0.0])
    found = branch_and_bound_search(
        world, seen_from(world, truth, 10.0), truth + [1.0, 0.0, 0.0], GlobalWindow(half_width_m=10.0)
    )
    assert found.ambiguity > 0.9


def test_block_sums_are_the_clipped_lookups_bit_for_bit() -> None:
    """``_sum_at`` (flat, in-place clipping) gives the bits of the plain ``np.clip`` + 2-D lookup it replaced.

    Lookups fall off every side of the table (clipped to its edge) and the nodes span more than one chunk.
    """
    rng = np.random.default_rng(7)
    table = rng.random((37, 53))
    # Rotations 0-4 reach past every edge; 5-7 stay well inside, so most of their nodes need no clipping.
    base = np.concatenate([rng.integers(-12, 66, size=(5, 40, 2)), rng.integers(10, 27, size=(3, 40, 2))])
    rot = rng.integers(0, 8, size=9000)
    origin = rng.integers(-9, 9, size=(9000, 2))
    kept = base.copy()
    idx = np.clip(base[rot] + origin[:, None, :], 0, np.array(table.shape) - 1)
    expected = table[idx[..., 0], idx[..., 1]].sum(axis=1)
    inside = ((base[rot] + origin[:, None, :] >= 0) & (base[rot] + origin[:, None, :] < table.shape)).all(axis=(1, 2))
    assert 1000 < inside.sum() < 8000  # both kinds of node, in every chunk
    for n in (9000, 513, 1):  # whole chunks and a short last one; a single node
        assert _sum_at(table, base, rot[:n], origin[:n]).tobytes() == expected[:n].tobytes()
    for axis, last in enumerate((36, 52)):  # every edge was reached, so the clipping was exercised
        assert (idx[..., axis] == 0).any() and (idx[..., axis] == last).any()
    np.testing.assert_array_equal(base, kept)  # the rotated points are left as they were


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_correlative_scores_are_the_bounds_tested_lookups_bit_for_bit(seed: int) -> None:
    """The flat lookups with one appended zero give the bits of a bounds test and a clipped 2-D lookup.

    The field covers a small patch of a larger scan, so moved points fall outside it on every side: those
    score 0, not the edge value.
    """
    rng = np.random.default_rng(seed)
    world = random_walls(seed=seed)
    src = seen_from(world, np.array([1.0, -2.0, 0.4]))[::9]
    field, lo = likelihood_field(world[np.hypot(world[:, 0] - 1.0, world[:, 1] + 2.0) < 10.0], 0.1, 0.15)
    offsets = np.arange(-10, 11) * 0.2
    grid = np.stack(np.meshgrid(offsets, offsets, indexing="ij"), axis=-1).reshape(-1, 2)
    guess = np.array([1.0, -2.0, 0.4]) + rng.normal(0.0, 0.3, 3)
    thetas = guess[2] + np.arange(-5, 6) * math.radians(3.0)
    expected = []
    cells = []
    for theta in thetas:
        c, s = math.cos(theta), math.sin(theta)
        moved = src @ np.array([[c, s], [-s, c]]) + guess[:2]
        idx = np.floor((moved[None, :, :] + grid[:, None, :] - lo) / 0.1).astype(int)
        inside = (idx >= 0).all(axis=-1) & (idx < field.shape).all(axis=-1)
        vals = field[np.clip(idx[..., 0], 0, field.shape[0] - 1), np.clip(idx[..., 1], 0, field.shape[1] - 1)]
        expected.append(np.where(inside, vals, 0.0).sum(axis=1))
        cells.append(idx)
    every = np.concatenate(cells).reshape(-1, 2)
    for axis in (0, 1):  # lookups fell off both ends of both axes
        assert (every[:, axis] < 0).any() and (every[:, axis] >= field.shape[axis]).any()
    assert _pose_scores(field, lo, src, guess, grid, thetas, 0.1).tobytes() == np.array(expected).tobytes()


def test_the_zero_border_leaves_the_global_search_bit_for_bit(monkeypatch: pytest.MonkeyPatch) -> None:
    """Widening the pooled tables (no clipped lookups) finds the same pose, score and ambiguity, to the bit.

    The search's half-width reaches far beyond the field, so without the border most blocks need clipping.
    """
    world = random_walls(seed=5, extent_m=12.0)
    truth = np.array([2.0, 1.0, -0.3])
    source = seen_from(world, truth, 25.0)
    guess = truth + np.array([6.5, -4.0, math.radians(12.0)])
    window = GlobalWindow(half_width_m=20.0, half_angle_rad=math.radians(15.0))
    widened = branch_and_bound_search(world, source, guess, window)
    monkeypatch.setattr(correlative, "_zero_border", lambda tables, base, low, high: (tables, base))
    clipped = branch_and_bound_search(world, source, guess, window)
    assert widened.pose.tobytes() == clipped.pose.tobytes()
    assert (widened.score, widened.ambiguity) == (clipped.score, clipped.ambiguity)
    assert np.hypot(*(widened.pose[:2] - truth[:2])) < 0.3  # a real match, not two equal failures


def test_block_sums_on_the_zero_border_are_the_clipped_ones_bit_for_bit() -> None:
    """Every level's block sums read through the widened tables equal the clipped lookups of the padded field.

    As in the search, the field is padded by one more than the widest block, so each pooled level's edge cells
    are zero; points and origins reach far past every side, so most nodes would need clipping.
    """
    rng = np.random.default_rng(11)
    levels = 3
    field = rng.random((30, 41))
    pooled = _pooled_fields(np.pad(field, 2**levels + 1), levels)
    base = rng.integers(-20, 70, size=(4, 50, 2))
    low, high = -24, 23
    rot = rng.integers(0, 4, size=3000)
    origin = rng.integers(low, high + 1, size=(3000, 2))
    widened, shifted = _zero_border(pooled, base, low, high)
    assert widened[0].shape[0] > pooled[0].shape[0] and widened[0].shape[1] > pooled[0].shape[1]
    n0, n1 = pooled[0].shape
    reach = base[rot] + origin[:, None, :]
    clipped = ~((reach >= 0) & (reach < (n0, n1))).all(axis=(1, 2))
    assert clipped.mean() > 0.5
    for h in range(levels + 1):
        assert _sum_at(widened[h], shifted, rot, origin).tobytes() == _sum_at(pooled[h], base, rot, origin).tobytes()
