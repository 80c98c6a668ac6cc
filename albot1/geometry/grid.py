"""Thinning a point cloud on a square grid: the first point in each cell, in input order.

One implementation for every cloud the package thins (the stored point maps
of the baselines, the clouds the graph baseline registers, both sides of the
map-shape metric): deterministic (the first point to reach a cell wins, so
the result does not depend on a hash order or a random draw) and
vectorised (one ``np.unique`` of one int64 key per point).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray

__all__ = ["cell_keys", "first_per_cell"]


def cell_keys(points: FloatArray, cell_m: float) -> NDArray[np.int64]:
    """One int64 key per ``cell_m`` grid cell of each finite point ``(K, 2)`` (x in the high, y in the low 32 bits).

    Distinct cells get distinct keys while cell indices fit in 32 bits
    (``|coordinate| < 2**31 * cell_m``, thousands of kilometres at centimetre cells).
    """
    cells = np.floor(points / cell_m).astype(np.int64)
    return (cells[:, 0] << 32) | (cells[:, 1] & 0xFFFFFFFF)


def first_per_cell(points: FloatArray, cell_m: float) -> FloatArray:
    """The first point of ``points`` ``(K, 2)`` in each ``cell_m`` grid cell, in input order (one-shot thinning)."""
    _, first = np.unique(cell_keys(points, cell_m), return_index=True)
    return points[np.sort(first)]
