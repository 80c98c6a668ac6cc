"""Coarse correlative search: a starting pose for ICP when the guess may be metres off.

After a long loop the estimate can have drifted several metres, far outside
ICP's basin of convergence. Following Olson (2009, "Real-time correlative
scan matching"), the target is rasterised into a likelihood field
(``exp(-d^2 / 2 sigma^2)`` of the distance to the nearest target point) and
every pose of a translation x rotation grid around the guess is scored by
summing the field at the moved source points; the best pose seeds ICP, which
then does the precise work and the acceptance tests judge the result.
numpy/scipy, and one compiled kernel for the place search's block sums
(:mod:`.block_sums`); no I/O.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph.block_sums import block_sums, pose_sums


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


def likelihood_field(target: FloatArray, cell_m: float, sigma_m: float) -> tuple[FloatArray, FloatArray]:
    """``exp(-d^2 / 2 sigma^2)`` of the distance ``d`` to the nearest target point, on a grid; (field, origin).

    The grid covers the target plus a margin of ``3 sigma``; cell ``(i, j)``
    holds the point ``origin + (i, j) * cell_m``.
    """
    from scipy.ndimage import distance_transform_edt

    margin = 3.0 * sigma_m
    lo = target.min(axis=0) - margin
    shape = np.ceil((target.max(axis=0) + margin - lo) / cell_m).astype(int) + 1
    occupied = np.ones(tuple(shape), dtype=bool)
    cells = np.floor((target - lo) / cell_m).astype(int)
    occupied[cells[:, 0], cells[:, 1]] = False
    dist = distance_transform_edt(occupied) * cell_m
    return np.exp(-0.5 * (dist / sigma_m) ** 2), lo


def correlative_search(
    target: FloatArray, source: FloatArray, guess: FloatArray, window: SearchWindow = SearchWindow()
) -> CoarseMatch:
    """The best-scoring pose of the search grid around ``guess`` (see :class:`CoarseMatch`)."""
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
    field, lo = likelihood_field(tgt[near], window.cell_m, window.sigma_m)
    n_t = int(round(window.half_width_m / window.step_m))
    offsets = np.arange(-n_t, n_t + 1) * window.step_m
    grid = np.stack(np.meshgrid(offsets, offsets, indexing="ij"), axis=-1).reshape(-1, 2)
    n_r = int(round(window.half_angle_rad / window.step_rad))
    thetas = guess[2] + np.arange(-n_r, n_r + 1) * window.step_rad
    scores = _pose_scores(field, lo, src, guess, grid, thetas, window.cell_m)
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


def _pose_scores(
    field: FloatArray,
    lo: FloatArray,
    src: FloatArray,
    guess: FloatArray,
    grid: FloatArray,
    thetas: FloatArray,
    cell_m: float,
) -> FloatArray:
    """``scores[r, g]``: the sum of ``field`` at ``src`` turned by ``thetas[r]`` and moved to ``guess + grid[g]``.

    A point outside the field scores 0. The points are turned by numpy
    (``src @ R``: BLAS) and moved to the guess here; the lookups and the row
    sums are one compiled pass (:func:`.block_sums.pose_sums`) with the same
    cells, values and sums as the numpy formulation, which read the field
    through its flat table with one zero appended (every outside lookup went
    there: unsigned, a negative cell index is huge, so one comparison per
    axis found them) and summed each row with ``sum(axis=1)`` (a unit test
    compares the bits with it and with a bounds test and clipped 2-D lookup).
    """
    moved = np.empty((len(thetas), len(src), 2))
    for r, theta in enumerate(thetas):
        c, s = math.cos(theta), math.sin(theta)
        moved[r] = src @ np.array([[c, s], [-s, c]]) + guess[:2]
    scores = np.empty((len(thetas), len(grid)))
    field64 = np.ascontiguousarray(field, dtype=np.float64)
    pose_sums(field64, moved, np.ascontiguousarray(grid, dtype=np.float64), float(lo[0]), float(lo[1]), cell_m, scores)
    return scores


@dataclass(frozen=True)
class GlobalWindow:
    """A wide search (tens of metres, tens of degrees) for :func:`branch_and_bound_search`.

    Translations are searched on the field's own grid (``cell_m``); the
    search tree's top blocks are ``2**levels`` cells wide, and ``max_nodes``
    caps the blocks alive at any level (beyond it the search gives up).
    """

    half_width_m: float = 30.0
    half_angle_rad: float = math.radians(30.0)
    step_rad: float = math.radians(1.0)
    cell_m: float = 0.2
    sigma_m: float = 0.3
    levels: int = 5
    max_points: int = 200
    max_nodes: int = 200_000
    min_ambiguity: float = 0.9
    ambiguity_radius_m: float = 2.0


def _pooled_fields(field: FloatArray, levels: int) -> list[FloatArray]:
    """``out[h][i, j] = max(field[i:i + 2**h, j:j + 2**h])`` (zeros beyond the end), for h = 0..levels."""
    out = [field]
    for h in range(1, levels + 1):
        s = 2 ** (h - 1)
        prev = np.pad(out[-1], ((0, s), (0, s)))
        n0, n1 = field.shape
        out.append(np.maximum(np.maximum(prev[:n0, :n1], prev[s:, :n1]), np.maximum(prev[:n0, s:], prev[s:, s:])))
    return out


def _sum_at(
    table: FloatArray, base: NDArray[np.int64], rot: NDArray[np.int64], origin: NDArray[np.int64]
) -> FloatArray:
    """For each node ``k``: the sum over source points of ``table[base[rot[k]] + origin[k]]`` (clipped lookups).

    Most of a search; one compiled pass (:func:`.block_sums.block_sums`) that
    gathers each node's values into one buffer and sums them as numpy sums a
    row, so the same indices, values and row sums as ``np.clip``, 2-D fancy
    indexing and ``sum(axis=1)`` (a unit test compares the bits), without the
    nodes x points temporaries (docs/baselines.md, "Cost (issue 24), third round").
    """
    out = np.empty(len(rot))
    block_sums(
        np.ascontiguousarray(table, dtype=np.float64),
        np.ascontiguousarray(base, dtype=np.int64),
        np.ascontiguousarray(rot, dtype=np.int64),
        np.ascontiguousarray(origin, dtype=np.int64),
        out,
    )
    return out


#: :func:`_zero_border` widens the search's tables up to this many cells (or 4x their own), else leaves the clipping.
_MAX_BORDER_CELLS = 1 << 20


def _zero_border(
    tables: list[FloatArray], base: NDArray[np.int64], low: int, high: int
) -> tuple[list[FloatArray], NDArray[np.int64]]:
    """``tables`` with a zero border wide enough that every lookup ``base + origin`` is inside; ``base`` shifted to it.

    ``origin`` is any block origin in ``[low, high]`` on both axes. Each table's
    edge cells are zeros (:func:`branch_and_bound_search` pads the field by
    more than its widest block), so a clipped lookup reads 0.0 and so does the
    same lookup in the border: every sum of :func:`_sum_at` keeps its bits,
    but no node needs clipping any more (the clipped path costs several
    times the plain one, and about half of fr-clinic's search nodes took it).
    Past a size bound the tables are left as they are and the clipping stays.
    """
    shape = np.array(tables[0].shape)
    before = np.maximum(0, -(base.min(axis=(0, 1)) + low))
    after = np.maximum(0, base.max(axis=(0, 1)) + high - (shape - 1))
    cells = int(np.prod(shape + before + after))
    if cells > max(4 * int(np.prod(shape)), _MAX_BORDER_CELLS):
        return tables, base
    widths = ((int(before[0]), int(after[0])), (int(before[1]), int(after[1])))
    return [np.pad(table, widths) for table in tables], base + before


def branch_and_bound_search(
    target: FloatArray, source: FloatArray, guess: FloatArray, window: GlobalWindow = GlobalWindow()
) -> CoarseMatch:
    """The best pose of a wide translation x rotation grid around ``guess``, found by branch and bound.

    An exhaustive search of +-40 m at 0.2 m and +-30 deg at 1 deg is ~2e9
    point lookups. Hess et al. (2016, Cartographer) bound whole blocks of
    translations instead: no translation inside a block scores more than the
    sum, over source points, of the field's maximum over the block (a
    max-pooled field, one lookup per point). Blocks are split in four level
    by level and those whose bound cannot beat ``min_ambiguity`` x the best
    score found are dropped (the first best comes from a greedy descent of
    the most promising top blocks). What survives to single cells is scored
    exactly, so the best pose is the grid's best and the rival test is exact
    too: any pose scoring more than ``min_ambiguity`` x the best is kept, and
    a kept pose farther than ``ambiguity_radius_m`` makes the match ambiguous
    (:class:`CoarseMatch`). When more than ``max_nodes`` blocks survive a
    level the search stops with ambiguity 1 (undecided).
    """
    src = np.asarray(source, dtype=float).reshape(-1, 2)
    if len(src) > window.max_points:
        src = src[np.linspace(0, len(src) - 1, window.max_points).astype(int)]
    tgt = np.asarray(target, dtype=float).reshape(-1, 2)
    if not len(src) or not len(tgt):
        return CoarseMatch(np.asarray(guess, dtype=float).copy(), 0.0, 1.0)
    top = 2**window.levels
    n_top = int(math.ceil(window.half_width_m / (top * window.cell_m)))
    field, lo = likelihood_field(tgt, window.cell_m, window.sigma_m)
    pad = top + 1  # a zero border: every pooled level's edge cells are 0, so clipped lookups read zeros
    pooled = _pooled_fields(np.pad(field, pad), window.levels)
    lo = lo - pad * window.cell_m
    n_r = int(round(window.half_angle_rad / window.step_rad))
    thetas = guess[2] + np.arange(-n_r, n_r + 1) * window.step_rad
    base = np.empty((len(thetas), len(src), 2), dtype=np.int64)
    for r, theta in enumerate(thetas):
        c, s = math.cos(theta), math.sin(theta)
        base[r] = np.floor((src @ np.array([[c, s], [-s, c]]) + guess[:2] - lo) / window.cell_m).astype(np.int64)
    starts = np.arange(-n_top, n_top) * top
    # Every block origin of the search lies in [-n_top * top, n_top * top - 1] on both axes.
    pooled, base = _zero_border(pooled, base, -n_top * top, n_top * top - 1)
    grid = np.stack(np.meshgrid(starts, starts, indexing="ij"), axis=-1).reshape(-1, 2)
    rot = np.repeat(np.arange(len(thetas)), len(grid))
    origin = np.tile(grid, (len(thetas), 1))
    bound = _sum_at(pooled[-1], base, rot, origin)
    quads = np.array([[0, 0], [0, 1], [1, 0], [1, 1]], dtype=np.int64)

    def split(rot: NDArray[np.int64], origin: NDArray[np.int64], h: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """The four children (level h - 1) of blocks at level h."""
        step = 2 ** (h - 1)
        return np.repeat(rot, 4), (origin[:, None, :] + step * quads[None, :, :]).reshape(-1, 2)

    # A first best score: descend greedily from the most promising top blocks.
    lead = np.argsort(-bound, kind="stable")[:16]
    d_rot, d_origin = rot[lead], origin[lead]
    for h in range(window.levels, 0, -1):
        c_rot, c_origin = split(d_rot, d_origin, h)
        c_bound = _sum_at(pooled[h - 1], base, c_rot, c_origin).reshape(-1, 4)
        pick = np.arange(len(d_rot)) * 4 + np.argmax(c_bound, axis=1)
        d_rot, d_origin = c_rot[pick], c_origin[pick]
    best = float(_sum_at(pooled[0], base, d_rot, d_origin).max())
    keep = bound > window.min_ambiguity * best
    rot, origin = rot[keep], origin[keep]
    for h in range(window.levels, 0, -1):
        if len(rot) > window.max_nodes:
            return CoarseMatch(np.asarray(guess, dtype=float).copy(), best / len(src), 1.0)
        rot, origin = split(rot, origin, h)
        bound = _sum_at(pooled[h - 1], base, rot, origin)
        if h == 1:
            best = max(best, float(bound.max(initial=0.0)))
        keep = bound > window.min_ambiguity * best
        rot, origin, bound = rot[keep], origin[keep], bound[keep]
    if best <= 0 or not len(bound):
        return CoarseMatch(np.asarray(guess, dtype=float).copy(), 0.0, 1.0)
    k = int(np.argmax(bound))
    poses = np.column_stack(
        [guess[0] + origin[:, 0] * window.cell_m, guess[1] + origin[:, 1] * window.cell_m, thetas[rot]]
    )
    far = np.hypot(poses[:, 0] - poses[k, 0], poses[:, 1] - poses[k, 1]) > window.ambiguity_radius_m
    rival = float(bound[far].max()) if far.any() else 0.0
    return CoarseMatch(poses[k], float(bound[k]) / len(src), rival / float(bound[k]))
