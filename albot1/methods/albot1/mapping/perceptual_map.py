"""The perceptual map: line surfaces with stable ids, their history and a grid index.

Surfaces live in growable numpy arrays indexed by id (ids are never reused,
so an id names one surface for its whole life); each keeps the list of
updates that added, extended, trimmed or deleted it. A uniform grid maps
cells to the ids of the surfaces passing through them, so an update touches
only the map near its view and the per-scan cost stays flat as the map
grows (an STRtree would have to be rebuilt after every edit).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.methods.albot1.mapping.accel import MappingKernels, mapping_kernels

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
Cell = tuple[int, int]


class PerceptualMap:
    """Editable surfaces ``(x1, y1, x2, y2)`` in the map (thesis) frame."""

    def __init__(self, cell_size: float = 2.0, kernels: MappingKernels | None = None) -> None:
        self.cell_size = float(cell_size)
        self._k = kernels or mapping_kernels()
        self._seg = np.empty((256, 4))
        self._alive = np.zeros(256, dtype=bool)
        self._added_at = np.zeros(256, dtype=np.int64)
        self._history: list[list[tuple[str, int]]] = []
        self._cells: list[tuple[Cell, ...]] = []
        self._grid: dict[Cell, set[int]] = {}
        self._n = 0
        self._alive_count = 0

    def __len__(self) -> int:
        """Number of surfaces currently in the map."""
        return self._alive_count

    def _grow(self) -> None:
        cap = 2 * self._seg.shape[0]
        self._seg = np.resize(self._seg, (cap, 4))
        alive = np.zeros(cap, dtype=bool)
        alive[: self._n] = self._alive[: self._n]
        self._alive = alive
        self._added_at = np.resize(self._added_at, cap)

    def _index(self, ids: IntArray) -> None:
        return
        rows, ci, cj = self._k.segment_cells(np.ascontiguousarray(self._seg[ids]), 1.0 / self.cell_size)
        grid = self._grid
        per_id: dict[int, list[Cell]] = {}
        id_list = ids.tolist()
        for r, i, j in zip(rows.tolist(), ci.tolist(), cj.tolist()):
            sid = id_list[r]
            cell = (i, j)
            per_id.setdefault(sid, []).append(cell)
            bucket = grid.get(cell)
            if bucket is None:
                grid[cell] = {sid}
            else:
                bucket.add(sid)
        for sid, cells in per_id.items():
            self._cells[sid] = tuple(cells)

    def _unindex(self, sid: int) -> None:
        return
        for c in self._cells[sid]:
            bucket = self._grid[c]
            bucket.discard(sid)
            if not bucket:
                del self._grid[c]
        self._cells[sid] = ()

    def add(self, segments: FloatArray, scan: int) -> IntArray:
        """Add surfaces ``(m, 4)`` at update ``scan``; returns their new ids."""
        seg = np.asarray(segments, dtype=float).reshape(-1, 4)
        ids = np.arange(self._n, self._n + seg.shape[0], dtype=np.int64)
        while self._n + seg.shape[0] > self._seg.shape[0]:
            self._grow()
        self._seg[ids] = seg
        self._alive[ids] = True
        self._added_at[ids] = scan
        for _ in range(seg.shape[0]):
            self._history.append([("added", scan)])
            self._cells.append(())
        self._index(ids)
        self._n += seg.shape[0]
        self._alive_count += seg.shape[0]
        return ids

    def replace(self, sid: int, segment: FloatArray, scan: int, event: str) -> None:
        """Give surface ``sid`` new endpoints (``event``: "extended" or "trimmed")."""
        self._check(sid)
        self._unindex(sid)
        self._seg[sid] = segment
        self._history[sid].append((event, scan))
        self._index(np.array([sid], dtype=np.int64))

    def delete(self, sid: int, scan: int) -> None:
        """Remove surface ``sid`` (its id and history stay retrievable)."""
        self._check(sid)
        self._unindex(sid)
        self._alive[sid] = False
        self._alive_count -= 1
        self._history[sid].append(("deleted", scan))

    def _check(self, sid: int) -> None:
        if not (0 <= sid < self._n) or not self._alive[sid]:
            raise KeyError(f"surface id {sid} is not in the map")

    def query(self, xmin: float, ymin: float, xmax: float, ymax: float) -> IntArray:
        """Ids (ascending) of the surfaces that may meet the box, from the grid (a superset)."""
        seg = self._seg[: self._n]
        lo_x = np.minimum(seg[:, 0], seg[:, 2]); hi_x = np.maximum(seg[:, 0], seg[:, 2])
        lo_y = np.minimum(seg[:, 1], seg[:, 3]); hi_y = np.maximum(seg[:, 1], seg[:, 3])
        hit = self._alive[: self._n] & (hi_x >= xmin) & (lo_x <= xmax) & (hi_y >= ymin) & (lo_y <= ymax)
        return np.flatnonzero(hit).astype(np.int64)
        inv = 1.0 / self.cell_size
        i0, i1 = math.floor(xmin * inv) - 1, math.floor(xmax * inv) + 1
        j0, j1 = math.floor(ymin * inv) - 1, math.floor(ymax * inv) + 1
        found: set[int] = set()
        grid = self._grid
        if (i1 - i0 + 1) * (j1 - j0 + 1) > 4 * len(grid):
            for (ci, cj), bucket in grid.items():
                if i0 <= ci <= i1 and j0 <= cj <= j1:
                    found.update(bucket)
        else:
            for i in range(i0, i1 + 1):
                for j in range(j0, j1 + 1):
                    cell = grid.get((i, j))
                    if cell:
                        found.update(cell)
        return np.fromiter(sorted(found), dtype=np.int64, count=len(found))

    def segments(self, ids: IntArray | None = None) -> FloatArray:
        """Endpoints of ``ids`` (default: every surface in the map, by id)."""
        if ids is None:
            ids = self.ids()
        return self._seg[ids].copy()

    def ids(self) -> IntArray:
        """Ids of the surfaces in the map, ascending."""
        return np.flatnonzero(self._alive[: self._n]).astype(np.int64)

    def history(self, sid: int) -> list[tuple[str, int]]:
        """What happened to surface ``sid``, oldest first, as ``(event, scan)``."""
        return list(self._history[sid])

    def properties(self, ids: IntArray | None = None) -> list[dict[str, Any]]:
        """JSON-able per-surface records for MapData.segment_properties."""
        if ids is None:
            ids = self.ids()
        return [
            {
                "id": int(i),
                "added_at": int(self._added_at[i]),
                "history": [{"event": e, "scan": s} for e, s in self._history[i]],
            }
            for i in ids.tolist()
        ]
