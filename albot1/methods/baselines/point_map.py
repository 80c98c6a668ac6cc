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

from albot1.geometry.grid import cell_keys
from albot1.geometry.types import FloatArray


class ThinnedPointMap:
    """2D points in the map frame, at most one per ``cell_m`` x ``cell_m`` grid cell.

    Points are buffered and thinned in batches of about ``batch_points``:
    one vectorised pass per batch costs a few microseconds per scan instead
    of a fixed per-call overhead in a mapper's timed per-scan update, and the
    result is the same as thinning scan by scan (first point per cell wins,
    in insertion order).
    """

    def __init__(self, cell_m: float, batch_points: int = 50_000) -> None:
        if not cell_m > 0:
            raise ValueError(f"expected a positive grid cell size, got {cell_m}")
        self.cell_m = cell_m
        self.batch_points = batch_points
        self._cells: set[int] = set()
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
        # One int64 key per cell keeps the bookkeeping in C-level set ops.
        unique, first = np.unique(cell_keys(points, self.cell_m), return_index=True)
        fresh_keys = set(unique.tolist()).difference(self._cells)
        if not fresh_keys:
            return
        self._cells.update(fresh_keys)
        fresh = np.fromiter(fresh_keys, dtype=np.int64, count=len(fresh_keys))
        self._kept.append(points[np.sort(first[np.isin(unique, fresh)])])

    def __len__(self) -> int:
        self._flush()
        return sum(len(chunk) for chunk in self._kept)

    def points(self) -> FloatArray:
        """All kept points, ``(K, 2)``, in insertion order."""
        self._flush()
        return np.concatenate(self._kept) if self._kept else np.empty((0, 2))
