"""Coarse correlative search: a starting pose for ICP when the guess may be metres off.

After a long loop the estimate can have drifted several metres, far outside
ICP's basin of convergence. Following Olson (2009, "Real-time correlative
scan matching"), the target is rasterised into a likelihood field
(``exp(-d^2 / 2 sigma^2)`` of the distance to the nearest target point) and
every pose of a translation x rotation grid around the guess is scored by
summing the field at the moved source points; the best pose seeds ICP, which
then does the precise work and the acceptance tests judge the result.
Pure numpy/scipy, no I/O.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class SearchWindow:
    """The grid searched around the guess."""

    half_width_m: float = 3.0
    step_m: float = 0.2
    half_angle_rad: float = math.radians(15.0)
    step_rad: float = math.radians(3.0)
    cell_m: float = 0.1
    sigma_m: float = 0.15
    max_points: int = 80
    ambiguity_radius_m: float = 1.0


@dataclass(frozen=True)
class CoarseMatch:
    """The best grid pose, its score (a fraction of the source points) and its ambiguity.

    ``ambiguity`` is the best score at least ``ambiguity_radius_m`` away from
    the best pose divided by the best score: near 1 means another, distinct
    alignment explains the scan about as well (a corridor with evenly spaced
    doors), so the match proves nothing.
    """

    pose: FloatArray
    score: float
    ambiguity: float


def correlative_search(
    target: FloatArray, source: FloatArray, guess: FloatArray, window: SearchWindow = SearchWindow()
) -> CoarseMatch:
    """The best-scoring pose of the search grid around ``guess`` (see :class:`CoarseMatch`)."""
    from scipy.ndimage import distance_transform_edt

    src = np.asarray(source, dtype=float).reshape(-1, 2)
    if len(src) > window.max_points:  # an even subsample keeps the cost bounded and deterministic
        src = src[np.linspace(0, len(src) - 1, window.max_points).astype(int)]
    tgt = np.asarray(target, dtype=float).reshape(-1, 2)
    margin = 3.0 * window.sigma_m
    # Only target points some moved source point can reach matter; the field's size (and cost) follows.
    reach = float(np.hypot(src[:, 0], src[:, 1]).max()) + math.sqrt(2.0) * window.half_width_m + margin
    near = np.abs(tgt - guess[:2]).max(axis=1) <= reach
    if not near.any():
        return CoarseMatch(np.asarray(guess, dtype=float).copy(), 0.0, 1.0)
    tgt = tgt[near]
    lo = tgt.min(axis=0) - margin
    shape = np.ceil((tgt.max(axis=0) + margin - lo) / window.cell_m).astype(int) + 1
    occupied = np.ones(tuple(shape), dtype=bool)
    cells = np.floor((tgt - lo) / window.cell_m).astype(int)
    occupied[cells[:, 0], cells[:, 1]] = False
    dist = distance_transform_edt(occupied) * window.cell_m
    field = np.exp(-0.5 * (dist / window.sigma_m) ** 2)

    n_t = int(round(window.half_width_m / window.step_m))
    offsets = np.arange(-n_t, n_t + 1) * window.step_m
    grid = np.stack(np.meshgrid(offsets, offsets, indexing="ij"), axis=-1).reshape(-1, 2)
    n_r = int(round(window.half_angle_rad / window.step_rad))
    thetas = guess[2] + np.arange(-n_r, n_r + 1) * window.step_rad
    scores = np.empty((len(thetas), len(grid)))
    for r, theta in enumerate(thetas):
        c, s = math.cos(theta), math.sin(theta)
        moved = src @ np.array([[c, s], [-s, c]]) + guess[:2]
        idx = np.floor((moved[None, :, :] + grid[:, None, :] - lo) / window.cell_m).astype(int)
        inside = (idx[..., 0] >= 0) & (idx[..., 0] < shape[0]) & (idx[..., 1] >= 0) & (idx[..., 1] < shape[1])
        vals = field[np.clip(idx[..., 0], 0, shape[0] - 1), np.clip(idx[..., 1], 0, shape[1] - 1)]
        scores[r] = np.where(inside, vals, 0.0).sum(axis=1)
    # Ties go to the pose nearest the guess: order by distance, argmax takes the first maximum.
    order = np.argsort(np.add.outer(np.abs(thetas - guess[2]), np.hypot(grid[:, 0], grid[:, 1])).ravel(), kind="stable")
    flat = scores.ravel()
    best = int(order[np.argmax(flat[order])])
    r, g = divmod(best, len(grid))
    best_pose = np.array([guess[0] + grid[g, 0], guess[1] + grid[g, 1], thetas[r]])
    # Ambiguity: the best score found farther than ``ambiguity_radius_m`` from the best pose (any rotation).
    far = np.hypot(grid[:, 0] - grid[g, 0], grid[:, 1] - grid[g, 1]) > window.ambiguity_radius_m
    rival = float(scores[:, far].max()) if far.any() else 0.0
    best_score = float(flat[best])
    return CoarseMatch(best_pose, best_score / len(src), rival / best_score if best_score > 0 else 1.0)
