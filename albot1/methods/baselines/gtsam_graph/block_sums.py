"""Place recognition's block sums in one compiled pass: numpy's own summation, so the same bits.

Why: a branch-and-bound place search (:func:`.correlative.branch_and_bound_search`)
scores hundreds of thousands of blocks, each the sum of a pooled table at its
source points, and that was over a third of gtsam-graph's CPU on fr-clinic
(docs/baselines.md, "Cost (issue 24), third round"), most of it numpy
gathering every block's lookups into a temporary array and reducing it.
Here each block's values are gathered into one small buffer and summed as
``ndarray.sum(axis=1)`` sums a row: numpy's pairwise summation
(``pairwise_sum`` of its ``add`` loops: eight running sums for rows of up to
128 values, their fixed combination, the rest added in order, longer rows
split in halves rounded down to a multiple of eight), from an initial 0.0.
IEEE additions in that order, no fast-math: the same bits as the numpy
formulation every recorded result came from (a unit test compares them on
rows of every length up to 300 and longer ones).

Lookups are clipped to the table, as ``np.clip`` and a 2-D lookup did.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import jitable, kernel
from albot1.methods.baselines.gtsam_graph.warming import warm_kernels

IntArray = NDArray[np.int64]

#: numpy's ``PW_BLOCKSIZE``: rows up to this long are summed with eight running sums, longer ones split in two
_BLOCK = 128
#: frames of the explicit recursion: rows up to 2**60 values
DEPTH = 64


@jitable
def _leaf(buf: FloatArray, lo: int, n: int) -> float:
    """numpy's pairwise sum of ``buf[lo:lo + n]`` for ``n <= 128``: eight running sums, then the rest in order."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += buf[i]
        return res
    r0, r1, r2, r3 = buf[lo], buf[lo + 1], buf[lo + 2], buf[lo + 3]
    r4, r5, r6, r7 = buf[lo + 4], buf[lo + 5], buf[lo + 6], buf[lo + 7]
    i = lo + 8
    end = lo + n - n % 8
    while i < end:
        r0 += buf[i]
        r1 += buf[i + 1]
        r2 += buf[i + 2]
        r3 += buf[i + 3]
        r4 += buf[i + 4]
        r5 += buf[i + 5]
        r6 += buf[i + 6]
        r7 += buf[i + 7]
        i += 8
    total: float = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < lo + n:
        total += buf[i]
        i += 1
    return total


@jitable
def pairwise_sum(buf: FloatArray, n: int, stack: IntArray, partial: FloatArray) -> float:
    """``buf[:n].sum()`` as numpy computes it: :func:`_leaf` on blocks, halves added as its recursion adds them.

    numba compiles no recursion here, so the recursion is an explicit stack
    (``stack``: rows of lo, n, stage; ``partial``: each frame's left half).
    """
    if n <= _BLOCK:
        return _leaf(buf, 0, n)
    top = 0
    stack[0, 0], stack[0, 1], stack[0, 2] = 0, n, 0
    ret = 0.0
    while top >= 0:
        lo, m = stack[top, 0], stack[top, 1]
        if m <= _BLOCK:
            ret = _leaf(buf, lo, m)
            top -= 1
            continue
        half = m // 2
        half -= half % 8
        stage = stack[top, 2]
        if stage == 0:  # the left half first
            stack[top, 2] = 1
            top += 1
            stack[top, 0], stack[top, 1], stack[top, 2] = lo, half, 0
        elif stage == 1:  # the left half is ``ret``: now the right one
            partial[top] = ret
            stack[top, 2] = 2
            top += 1
            stack[top, 0], stack[top, 1], stack[top, 2] = lo + half, m - half, 0
        else:
            ret = partial[top] + ret
            top -= 1
    return ret


@kernel
def block_sums(table: FloatArray, base: IntArray, rot: IntArray, origin: IntArray, out: FloatArray) -> None:
    """``out[k]``: the sum over source points ``p`` of ``table[clip(base[rot[k], p] + origin[k])]``, numpy's bits.

    The cell of each lookup is clipped to the table on each axis; the values
    are summed in the source points' order as ``ndarray.sum(axis=1)`` sums a
    row (:func:`pairwise_sum`). A node whose lookups all fall inside the table
    (every node of a search on its zero border) reads its rotation's flat
    cell indices plus one shift: one load per lookup instead of two, a clip
    and a product (the same cells, so the same values).
    """
    n0, n1 = table.shape
    rotations, points = base.shape[0], base.shape[1]
    if points == 0:  # numpy's sum of an empty row
        out[:] = 0.0
        return
    flat = table.ravel()
    cells = np.empty((rotations, points), dtype=np.int64)
    low = np.empty((rotations, 2), dtype=np.int64)
    high = np.empty((rotations, 2), dtype=np.int64)
    for r in range(rotations):
        low[r, 0], low[r, 1] = base[r, 0, 0], base[r, 0, 1]
        high[r, 0], high[r, 1] = base[r, 0, 0], base[r, 0, 1]
        for p in range(points):
            i, j = base[r, p, 0], base[r, p, 1]
            cells[r, p] = i * n1 + j
            low[r, 0], high[r, 0] = min(low[r, 0], i), max(high[r, 0], i)
            low[r, 1], high[r, 1] = min(low[r, 1], j), max(high[r, 1], j)
    buf = np.empty(points)
    stack = np.empty((DEPTH, 3), dtype=np.int64)
    partial = np.empty(DEPTH)
    for k in range(rot.shape[0]):
        r = rot[k]
        o0, o1 = origin[k, 0], origin[k, 1]
        if low[r, 0] + o0 >= 0 and high[r, 0] + o0 < n0 and low[r, 1] + o1 >= 0 and high[r, 1] + o1 < n1:
            shift = o0 * n1 + o1
            for p in range(points):
                buf[p] = flat[cells[r, p] + shift]
        else:
            for p in range(points):
                i = min(max(base[r, p, 0] + o0, 0), n0 - 1)
                j = min(max(base[r, p, 1] + o1, 0), n1 - 1)
                buf[p] = table[i, j]
        out[k] = 0.0 + pairwise_sum(buf, points, stack, partial)


@kernel
def pose_sums(
    field: FloatArray, moved: FloatArray, grid: FloatArray, lo0: float, lo1: float, cell_m: float, out: FloatArray
) -> None:
    """``out[r, g]``: the sum of ``field`` at ``moved[r]`` shifted by ``grid[g]``, 0 outside: the correlative scores.

    :func:`.correlative._pose_scores` as it was computed with numpy, lookup
    for lookup: the cell of a point is ``floor(v)`` of ``v = ((moved + grid)
    - lo) / cell_m`` on each axis (the same IEEE operations, no fast-math); a
    cell outside the field reads 0.0, and each row is summed as ``sum(axis=1)``
    sums it (:func:`pairwise_sum`, from 0.0). numpy kept exactly the floors in
    ``[0, n)`` (an unsigned test on the cast index: negative, NaN and
    out-of-range casts fail it); those are exactly the ``v`` with ``0 <= v < n``
    (``n`` is an integer; ``-0.0`` is kept, as its floor casts to 0), and for
    those the floor is the truncation ``int(v)``: so no ``floor`` call (a C
    library call here, most of the kernel's time) and no cast of a value out of
    range. Without the grid x points temporaries of every rotation
    (docs/baselines.md, "Cost (issue 24), fifth round").
    """
    n0, n1 = field.shape
    flat = field.ravel()
    rotations, points = moved.shape[0], moved.shape[1]
    buf = np.empty(points)
    stack = np.empty((DEPTH, 3), dtype=np.int64)
    partial = np.empty(DEPTH)
    for r in range(rotations):
        for g in range(grid.shape[0]):
            gx, gy = grid[g, 0], grid[g, 1]
            for p in range(points):
                vi = ((moved[r, p, 0] + gx) - lo0) / cell_m
                vj = ((moved[r, p, 1] + gy) - lo1) / cell_m
                if 0.0 <= vi < n0 and 0.0 <= vj < n1:
                    buf[p] = flat[int(vi) * n1 + int(vj)]
                else:
                    buf[p] = 0.0
            out[r, g] = 0.0 + pairwise_sum(buf, points, stack, partial)


#: :func:`line_moments` sums each point's neighbours in order, as numpy sums fewer than eight values; more go to numpy
MOMENT_NEIGHBOURS = 7


@kernel
def line_moments(
    pts: FloatArray,
    dist: FloatArray,
    idx: IntArray,
    counts: IntArray,
    cxx: FloatArray,
    cyy: FloatArray,
    cxy: FloatArray,
) -> None:
    """Each point's neighbour count and second moments about their mean, as :func:`.registration.line_normals` had numpy
    compute them from the k-d tree's ``dist`` and ``idx`` (``k <= MOMENT_NEIGHBOURS`` columns).

    The same operations per value: a neighbour is one with a finite
    distance (weight 1.0; the others are the point itself at weight 0.0),
    ``mean = sum(nb * w) / max(count, 1)``, ``d = (nb - mean) * w`` and the
    sums of ``d_x ** 2``, ``d_y ** 2`` and ``d_x * d_y``. numpy sums fewer than
    eight values one after the other from 0.0, whichever axis (its pairwise
    blocks start at eight), and so does this loop; no fast-math, so no fused
    multiply-add. One pass instead of about twenty numpy calls on ``(n, k, 2)``
    temporaries for every node's scan (docs/baselines.md, "Cost (issue 24), fifth round").
    """
    n, k = dist.shape
    for i in range(n):
        c = 0
        sx, sy = 0.0, 0.0
        for j in range(k):
            ok = math.isfinite(dist[i, j])
            q = idx[i, j] if ok else i
            w = 1.0 if ok else 0.0
            c += 1 if ok else 0
            sx += pts[q, 0] * w
            sy += pts[q, 1] * w
        mx, my = sx / max(c, 1), sy / max(c, 1)
        xx, yy, xy = 0.0, 0.0, 0.0
        for j in range(k):
            ok = math.isfinite(dist[i, j])
            q = idx[i, j] if ok else i
            w = 1.0 if ok else 0.0
            dx = (pts[q, 0] - mx) * w
            dy = (pts[q, 1] - my) * w
            xx += dx * dx
            yy += dy * dy
            xy += dx * dy
        counts[i], cxx[i], cyy[i], cxy[i] = c, xx, yy, xy


def sample_calls() -> list[tuple[str, Callable[..., Any], tuple[Any, ...]]]:
    """``(kernel name, kernel, arguments)`` typed as :func:`.correlative._sum_at` and ``_pose_scores`` call them.

    numba keys a cached kernel by its argument types, so these are a run's:
    C-ordered float64 tables, points and offsets, int64 index arrays.
    """
    table = np.arange(12.0).reshape(3, 4)
    base = np.array([[[0, 0], [2, 3], [-1, 5]]], dtype=np.int64)
    rot = np.zeros(2, dtype=np.int64)
    origin = np.array([[0, 0], [1, -1]], dtype=np.int64)
    moved = np.array([[[0.05, 0.05], [0.25, 0.35], [-1.0, 0.2]]])
    grid = np.array([[0.0, 0.0], [0.1, -0.1]])
    pts, dist = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0]]), np.array([[0.0, 1.0], [0.0, np.inf], [0.0, 1.0]])
    idx, out = np.array([[0, 1], [1, 3], [2, 0]], dtype=np.int64), np.empty(3)
    return [
        ("gtsam_graph.block_sums", block_sums, (table, base, rot, origin, np.empty(2))),
        ("gtsam_graph.pose_sums", pose_sums, (table, moved, grid, 0.0, 0.0, 0.1, np.empty((1, 2)))),
        ("gtsam_graph.line_moments", line_moments, (pts, dist, idx, np.empty(3, dtype=np.int64), out, out, out)),
    ]


def warm_up(announce: Callable[[str], None] | None = None) -> None:
    """Compile this module's kernels (or load numba's cache or the wheel's bundle) before a run's first scan."""
    warm_kernels((block_sums, pose_sums, line_moments), sample_calls, "block sums", announce)
