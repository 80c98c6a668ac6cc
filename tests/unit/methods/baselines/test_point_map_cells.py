"""ThinnedPointMap's claimed cells: a sorted int64 array, the same points as the set it replaced (session 26).

The map of an odometry cell on fr-clinic claims ~500,000 cells; a Python set of their keys cost ~50 bytes a
cell and most of the map's CPU. These tests hold the replacement to the same output as first-point-per-cell
order on inputs where a search in a sorted array is easy to get wrong (keys below, between and above every
claimed one, a batch of only claimed cells, negative cells whose int64 keys sort before positive ones) and
to its memory.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from albot1.geometry.grid import cell_keys
from albot1.methods.baselines.point_map import ThinnedPointMap


def _first_per_cell_by_set(chunks: list[np.ndarray], cell: float) -> np.ndarray:
    """The set-based bookkeeping ThinnedPointMap used until session 26, applied point by point."""
    claimed: set[int] = set()
    kept = []
    for chunk in chunks:
        for key, point in zip(cell_keys(chunk, cell).tolist(), chunk, strict=True):
            if key not in claimed:
                claimed.add(key)
                kept.append(point)
    return np.asarray(kept, dtype=float).reshape(-1, 2)


@pytest.mark.parametrize("batch", [1, 7, 64, 50_000])
def test_claimed_cells_below_between_and_above_keep_the_first_point(batch: int) -> None:
    cell = 0.5
    chunks = [
        np.array([[0.1, 0.1], [10.2, 10.2], [5.1, 5.1]]),  # three cells
        np.array([[-3.3, 0.2], [0.2, 0.3], [20.0, -1.0]]),  # below every claimed key, a claimed cell, above all
        np.array([[5.2, 5.3], [10.4, 10.3]]),  # only claimed cells: nothing kept
        np.array([[7.7, 7.7], [2.6, 2.6], [7.8, 7.6], [-3.4, 0.4], [-100.0, -100.0]]),  # between, a repeat
        np.array([[0.0, -0.0], [-0.0, 0.0], [-1e-9, 1e-9]]),  # the cells at and just below zero
    ]
    thinned = ThinnedPointMap(cell, batch_points=batch)
    for chunk in chunks:
        thinned.add(chunk)
    expected = _first_per_cell_by_set(chunks, cell)
    assert thinned.points().tobytes() == expected.tobytes()
    assert len(thinned) == len(expected) == 9


def test_a_long_random_walk_keeps_the_same_points_as_the_set() -> None:
    rng = np.random.default_rng(26)
    centres = np.cumsum(rng.normal(0.0, 0.3, size=(400, 2)), axis=0)
    chunks = [centre + rng.normal(0.0, 2.0, size=(60, 2)) for centre in centres]
    thinned = ThinnedPointMap(0.05, batch_points=1_000)
    for chunk in chunks:
        thinned.add(chunk)
    expected = _first_per_cell_by_set(chunks, 0.05)
    assert 10_000 < len(expected) < 24_000  # many cells, many of them revisited
    assert thinned.points().tobytes() == expected.tobytes()


def test_the_claimed_cells_cost_about_eight_bytes_each() -> None:
    cells = 100_000
    points = (np.arange(cells, dtype=float)[:, None] * np.array([[1.0, 0.0]]) + 0.5) * 0.05  # one point a cell
    thinned = ThinnedPointMap(0.05, batch_points=10_000)
    tracemalloc.start()
    try:
        for chunk in np.array_split(points, 100):
            thinned.add(chunk)
        assert len(thinned) == cells
        held, _ = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    kept = 16 * cells  # the kept points themselves: two float64 each
    # a sorted int64 array: 8 bytes a cell (the set of Python ints it replaced held ~50-60)
    assert held - kept < 12 * cells
