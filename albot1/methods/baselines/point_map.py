"""A point map thinned on a grid: the storable map of scan-projecting baselines.

Every scan projected with its pose would give millions of points on a long
log (13,631 Intel scans x 180 beams); keeping only the first point that
falls into each grid cell bounds the map by the area covered, keeps the
picture and the map-shape metrics meaningful, and is deterministic (the
first scan to see a cell wins). The one-shot form of the same thinning is
:func:`albot1.geometry.grid.first_per_cell`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.grid import cell_keys
from albot1.geometry.types import FloatArray


class ThinnedPointMap:
    """2D points in the map frame, at most one per ``cell_m`` x ``cell_m`` grid cell.

    Points are buffered and thinned in batches of about ``batch_points``:
    one vectorised pass per batch costs a few microseconds per scan instead
    of a fixed per-call overhead in a mapper's timed per-scan update, and the
    result is the same as thinning scan by scan (first point per cell wins,
    in insertion order).

    The cells already claimed are one sorted int64 array (:func:`cell_keys`), searched and extended by numpy;
    until session 26 they were a Python set of ints, and turning each batch's keys into Python ints and
    through the set's difference and update was most of the map's cost: 0.6-0.9 CPU-s of an odometry cell on
    fr-clinic (505,764 cells), about 50 bytes a cell where the array holds 8 (docs/benchmarking.md,
    "Session 26: the cell cost that grows with the log").
    """

    def __init__(self, cell_m: float, batch_points: int = 50_000) -> None:
        if not cell_m > 0:
            raise ValueError(f"expected a positive grid cell size, got {cell_m}")
        self.cell_m = cell_m
        self.batch_points = batch_points
        self._claimed: NDArray[np.int64] = np.empty(0, dtype=np.int64)  # sorted, each cell once
        self._kept: list[FloatArray] = []
        self._pending: list[FloatArray] = []
        self._pending_count = 0

    def add(self, points: FloatArray) -> None:
        """Queue ``points`` (K, 2); the cells they fall in are claimed in the order of ``add`` calls."""
        if len(points):
            self._pending.append(np.asarray(points, dtype=float))
            self._pending_count += len(points)
            if self._pending_count >= self.batch_points:
                self._flush()

    def _flush(self) -> None:
        if not self._pending:
            return
        points = np.concatenate(self._pending)
        self._pending, self._pending_count = [], 0
        # One int64 key per cell keeps the bookkeeping in numpy: a sort, a search and an insert per batch.
        unique, first = np.unique(cell_keys(points, self.cell_m), return_index=True)  # sorted; first occurrences
        claimed = self._claimed
        at = np.searchsorted(claimed, unique)  # where each key is, or would be inserted, in the claimed cells
        fresh = np.ones(len(unique), dtype=np.bool_)
        inside = at < len(claimed)
        fresh[inside] = claimed[at[inside]] != unique[inside]
        if not fresh.any():
            return
        self._claimed = np.insert(claimed, at[fresh], unique[fresh])  # still sorted: positions in the old array
        self._kept.append(points[np.sort(first[fresh])])

    def __len__(self) -> int:
        self._flush()
        return sum(len(chunk) for chunk in self._kept)

    def points(self) -> FloatArray:
        """All kept points, ``(K, 2)``, in insertion order."""
        self._flush()
        return np.concatenate(self._kept) if self._kept else np.empty((0, 2))
