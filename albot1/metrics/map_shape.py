"""Map shape: does the method's map agree with the reference map, in numbers?

The thesis judges its map by eye ("it maintains the overall shape"). Here
the *reference map* is every scan projected with its reference pose, and the
method's map geometry (segments sampled every few centimetres, or points) is
moved into the reference frame with the rigid alignment of the method's
trajectory to the reference trajectory (the same motion ATE removes; the
map is never aligned on its own, which would hide a wrong trajectory).
Then, with tolerance ``tol`` (default 0.3 m, about a corridor wall's
thickness plus laser noise):

``precision``  fraction of map geometry within ``tol`` of a reference point
               (how much of what the method drew is really there);
``coverage``   fraction of reference points within ``tol`` of the map
               (how much of what was seen the method kept; Albot1 forgets
               by design, so expect less than 1);
``mean_distance_m`` / ``median_distance_m`` from map geometry to the nearest
               reference point, and the same from reference to map.

Both clouds are thinned on a ``voxel_m`` grid first (the first point in each
cell, in input order): a wall scanned a thousand times must not outweigh a
wall scanned once, and the thinning is deterministic. If a cloud is still
larger than ``max_points`` it is strided evenly (deterministic again).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from albot1.geometry.grid import first_per_cell
from albot1.geometry.types import FloatArray
from albot1.metrics.errors import MetricsError

TOLERANCE_M = 0.3
VOXEL_M = 0.1
MAX_POINTS = 200_000
#: How the KD-trees are built: split at the midpoint (sliding), not the median, and nodes not shrunk to their
#: points. The nearest neighbour, and its distance, are the same whatever the tree's shape; on the maps of a
#: bench cell (points along walls) the two trees are built and queried in ~0.6 of the time (34 -> 21 ms a cell,
#: docs/benchmarking.md, "Session 24").
KD_TREE_OPTIONS = {"balanced_tree": False, "compact_nodes": False}


def thin(points: ArrayLike, voxel_m: float = VOXEL_M, max_points: int = MAX_POINTS) -> FloatArray:
    """Deterministic voxel thinning (first point per cell), then an even stride down to ``max_points``."""
    pts: FloatArray = np.asarray(points, dtype=float).reshape(-1, 2)
    pts = pts[np.isfinite(pts).all(axis=1)]
    if len(pts) == 0:
        return pts
    kept = first_per_cell(pts, voxel_m)
    if len(kept) > max_points:
        kept = kept[np.linspace(0, len(kept) - 1, max_points).astype(np.int64)]
    return kept


def map_agreement(
    map_points: ArrayLike,
    reference_points: ArrayLike,
    *,
    tol: float = TOLERANCE_M,
    voxel_m: float = VOXEL_M,
    max_points: int = MAX_POINTS,
    reference_thinned: bool = False,
) -> dict[str, Any]:
    """Precision, coverage and distances between two point sets in the same frame (m).

    ``reference_thinned``: ``reference_points`` is already ``thin(..., voxel_m,
    max_points)`` (a cached reference map); thinning is idempotent, so this only
    saves doing it again.
    """
    from scipy.spatial import cKDTree

    if tol <= 0:
        raise MetricsError(f"map shape: expected a positive tolerance, got {tol} m")
    mp = thin(map_points, voxel_m, max_points)
    rp = np.asarray(reference_points, dtype=float) if reference_thinned else thin(reference_points, voxel_m, max_points)
    if len(mp) == 0:
        raise MetricsError("map shape: the method's map has no geometry to compare")
    if len(rp) == 0:
        raise MetricsError("map shape: the reference map is empty (no valid beams in the scans)")
    map_to_ref, _ = cKDTree(rp, **KD_TREE_OPTIONS).query(mp)
    ref_to_map, _ = cKDTree(mp, **KD_TREE_OPTIONS).query(rp)
    return {
        "tolerance_m": tol,
        "voxel_m": voxel_m,
        "map_points": int(len(mp)),
        "reference_points": int(len(rp)),
        "precision": float(np.mean(map_to_ref <= tol)),
        "coverage": float(np.mean(ref_to_map <= tol)),
        "map_to_reference_mean_m": float(np.mean(map_to_ref)),
        "map_to_reference_median_m": float(np.median(map_to_ref)),
        "reference_to_map_mean_m": float(np.mean(ref_to_map)),
        "reference_to_map_median_m": float(np.median(ref_to_map)),
    }
