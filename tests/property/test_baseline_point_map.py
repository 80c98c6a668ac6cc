"""ThinnedPointMap: batching never changes the result, and it is "first point per cell"."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.methods.baselines.point_map import ThinnedPointMap

coordinate = st.floats(min_value=-50.0, max_value=50.0, allow_nan=False, allow_infinity=False)
scan = st.lists(st.tuples(coordinate, coordinate), min_size=0, max_size=30)


def _reference(chunks: list[np.ndarray], cell: float) -> np.ndarray:
    """First point per cell, by a plain loop over the points in order."""
    seen: set[tuple[int, int]] = set()
    kept = []
    for chunk in chunks:
        for x, y in chunk:
            key = (int(np.floor(x / cell)), int(np.floor(y / cell)))
            if key not in seen:
                seen.add(key)
                kept.append((x, y))
    return np.asarray(kept, dtype=float).reshape(-1, 2)


@settings(max_examples=150, deadline=None)
@given(
    scans=st.lists(scan, min_size=1, max_size=8),
    cell=st.sampled_from([0.05, 0.5, 3.0]),
    batch=st.integers(min_value=1, max_value=100),
)
def test_batched_thinning_equals_first_point_per_cell(
    scans: list[list[tuple[float, float]]], cell: float, batch: int
) -> None:
    chunks = [np.asarray(s, dtype=float).reshape(-1, 2) for s in scans]
    thinned = ThinnedPointMap(cell, batch_points=batch)
    for chunk in chunks:
        thinned.add(chunk)
    expected = _reference(chunks, cell)
    np.testing.assert_array_equal(thinned.points(), expected)
    assert len(thinned) == len(expected)
