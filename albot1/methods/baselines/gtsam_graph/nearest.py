"""ICP's correspondences without scipy's k-d tree where the answer cannot differ from it: a compiled grid search.

Why: half of gtsam-graph's CPU on the sparse corrected logs was
``cKDTree.query`` inside ICP (about 0.5 us per query point, docs/baselines.md,
"Cost"), and the recorded results are defined by its answers. So the grid
search here must give the same correspondence as ``cKDTree.query(moved, k=1,
distance_upper_bound=gate)`` followed by ``dist < gate``, bit for bit, and it
does so by deferring: a point whose answer the k-d tree could give differently
is marked and handed to the k-d tree itself (:meth:`Matches.find`).

Where could they differ? The k-d tree returns the first point it meets among
points at exactly the same squared distance (its traversal order), and its
pruning compares lower bounds summed in floating point, which can be a few
units in the last place off, near its distance bound (the gate squared, or
the best distance found so far). Both can only matter when two candidate
distances, or the best distance and the gate squared, are within that
rounding of each other. The grid search finds the nearest and second-nearest
squared distances exactly among every point that could be within the gate,
and marks a query as *ambiguous* when the two are within ``TIE_TOLERANCE`` of
the gate squared of each other, or the nearest is that close to the gate
squared; such a margin (1e-9 relative) is about a million times the rounding
of either computation. Everything else has one nearest point by a clear
margin, clearly inside or outside the gate, so both searches name it.

The grid: the target's points sorted into square cells (counting sort), the
query searched ring by ring of cells around its own until the next ring
cannot hold a point within the bound. The terms of the linearisation
(residual, Jacobian row, Cauchy weight, weighted row) are computed in the same kernel with
the same operations in the same order as the numpy formulation they replace
(no fast-math, so no fused multiply-add), written into arrays numpy allocated.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.albot1 import compiled
from albot1.methods.albot1.compiled import jitable, kernel
from albot1.methods.baselines.gtsam_graph.errors import RegistrationError
from albot1.methods.baselines.gtsam_graph.warming import warm_kernels

#: ambiguous when two squared distances (or one and the gate squared) are this close, relative to the gate squared
#: plus the gate times the coordinates' size (the k-d tree's rounding grows with both: see :func:`_nearest_one`)
TIE_TOLERANCE = 1e-9
#: the cell size of a target's grid (m); only the speed depends on it (measured in docs/baselines.md, "Cost, continued")
CELL_M = 0.2
#: a grid has at most this many cells per point (plus a constant): a sparse, wide target gets coarser cells
MAX_CELLS_PER_POINT = 4
#: idx of a query with no target point within the gate
NONE = -1
#: idx of an ambiguous query, left to the k-d tree
AMBIGUOUS = -2

IntArray = NDArray[np.int64]


class Grid:
    """A target's points sorted into square cells: ``xy`` in cell order, ``order`` their indices in the target."""

    def __init__(self, points: FloatArray) -> None:
        pts = np.ascontiguousarray(points, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[0] == 0 or pts.shape[1] != 2 or not np.isfinite(pts).all():
            raise RegistrationError(f"grid search: expected a non-empty (n, 2) array of finite points, got {pts.shape}")
        origin, dims, cell, starts, order = build_grid(pts, CELL_M, MAX_CELLS_PER_POINT)
        self.origin: FloatArray = origin
        self.dims: IntArray = dims
        self.cell: float = float(cell)
        self.starts: IntArray = starts
        self.order: IntArray = order
        self.xy: FloatArray = np.ascontiguousarray(pts[order])


@kernel
def build_grid(
    points: FloatArray, cell: float, max_cells_per_point: int
) -> tuple[FloatArray, IntArray, float, IntArray, IntArray]:
    """Origin, (nx, ny), cell size, CSR cell starts (cell ``cx * ny + cy``) and the points' order by cell."""
    n = points.shape[0]
    lo_x, lo_y = points[0, 0], points[0, 1]
    hi_x, hi_y = lo_x, lo_y
    for i in range(1, n):
        lo_x = min(lo_x, points[i, 0])
        lo_y = min(lo_y, points[i, 1])
        hi_x = max(hi_x, points[i, 0])
        hi_y = max(hi_y, points[i, 1])
    nx = int((hi_x - lo_x) / cell) + 1
    ny = int((hi_y - lo_y) / cell) + 1
    while nx * ny > max_cells_per_point * n + 64:
        cell *= 2.0
        nx = int((hi_x - lo_x) / cell) + 1
        ny = int((hi_y - lo_y) / cell) + 1
    starts = np.zeros(nx * ny + 1, dtype=np.int64)
    cells = np.empty(n, dtype=np.int64)
    for i in range(n):
        cx = min(int((points[i, 0] - lo_x) / cell), nx - 1)
        cy = min(int((points[i, 1] - lo_y) / cell), ny - 1)
        cells[i] = cx * ny + cy
        starts[cells[i] + 1] += 1
    for c in range(nx * ny):
        starts[c + 1] += starts[c]
    fill = starts[:-1].copy()
    order = np.empty(n, dtype=np.int64)
    for i in range(n):
        order[fill[cells[i]]] = i
        fill[cells[i]] += 1
    origin = np.empty(2)
    origin[0], origin[1] = lo_x, lo_y
    dims = np.empty(2, dtype=np.int64)
    dims[0], dims[1] = nx, ny
    return origin, dims, cell, starts, order


@jitable
def _scan_cells(
    xy: FloatArray,
    starts: IntArray,
    ny: int,
    cx: int,
    cy0: int,
    cy1: int,
    qx: float,
    qy: float,
    best: float,
    second: float,
    at: int,
) -> tuple[float, float, int]:
    """Cells ``cx, cy0..cy1`` (already clipped to the grid): the nearest and second-nearest squared distances."""
    for c in range(cx * ny + cy0, cx * ny + cy1 + 1):
        for k in range(starts[c], starts[c + 1]):
            dx = xy[k, 0] - qx
            dy = xy[k, 1] - qy
            d = dx * dx + dy * dy
            if d < best:
                second = best
                best = d
                at = k
            elif d < second:
                second = d
    return best, second, at


@jitable
def _nearest_one(
    origin: FloatArray,
    dims: IntArray,
    cell: float,
    starts: IntArray,
    xy: FloatArray,
    qx: float,
    qy: float,
    gate2: float,
) -> tuple[int, bool]:
    """The cell-order index of the point nearest ``(qx, qy)`` within the gate (-1: none) and whether it is ambiguous.

    The k-d tree rounds its squared distances and bounds with an error that grows with the gate and with the
    coordinates' size (``q - p`` and ``q - bound`` of numbers ``scale`` large, squared and summed: a few units
    of ``eps * gate * scale``), so the tolerance is ``TIE_TOLERANCE`` times ``gate2 + gate * scale``: about a
    million times that rounding at any scale (at 1e6 m, UTM-sized, as at 10 m). A query that is not finite is
    left to the tree (which refuses it, as it always did); the rings stop at the grid's far side whatever the
    bounds say.
    """
    if not (math.isfinite(qx) and math.isfinite(qy)):
        return -1, True
    nx, ny = dims[0], dims[1]
    far_x = max(abs(origin[0]), abs(origin[0] + nx * cell))
    far_y = max(abs(origin[1]), abs(origin[1] + ny * cell))
    scale = max(far_x, far_y, abs(qx), abs(qy))
    tol = TIE_TOLERANCE * (gate2 + math.sqrt(gate2) * scale)
    margin = 1e-6 * cell  # cells are assigned by rounded divisions: a ring's bound is kept this much looser
    reach = math.sqrt(gate2 + tol) + margin
    rings = int(reach / cell) + 2
    # Far outside the grid, clip the query's cell (the rings that could reach the grid are all that matter).
    fx = min(max(math.floor((qx - origin[0]) / cell), -rings - 1.0), nx + rings + 1.0)
    fy = min(max(math.floor((qy - origin[1]) / cell), -rings - 1.0), ny + rings + 1.0)
    ix, iy = int(fx), int(fy)
    # How far the query is inside its own cell: every point of ring r >= 1 is at least (r - 1) cells plus this away.
    x0, y0 = origin[0] + ix * cell, origin[1] + iy * cell
    inside = max(min(qx - x0, x0 + cell - qx, qy - y0, y0 + cell - qy) - margin, 0.0)
    best, second, at = np.inf, np.inf, -1
    r = 0
    while True:
        lo, hi = max(iy - r, 0), min(iy + r, ny - 1)
        if lo <= hi:
            if 0 <= ix - r < nx:
                best, second, at = _scan_cells(xy, starts, ny, ix - r, lo, hi, qx, qy, best, second, at)
            if r and 0 <= ix + r < nx:
                best, second, at = _scan_cells(xy, starts, ny, ix + r, lo, hi, qx, qy, best, second, at)
            for cx in range(max(ix - r + 1, 0), min(ix + r - 1, nx - 1) + 1):
                if iy - r >= 0:
                    best, second, at = _scan_cells(xy, starts, ny, cx, iy - r, iy - r, qx, qy, best, second, at)
                if r and iy + r < ny:
                    best, second, at = _scan_cells(xy, starts, ny, cx, iy + r, iy + r, qx, qy, best, second, at)
        below = r * cell + inside - margin  # every point of the next ring is farther than this
        if below > 0.0 and below * below > min(best, gate2) + tol:
            break
        if r > nx + ny + 2 * rings + 2:  # every cell of the grid has been searched
            break
        r += 1
    if at < 0 or best >= gate2 + tol:
        return -1, False
    return at, best > gate2 - tol or second - best <= tol


@kernel
def linearise_terms(
    origin: FloatArray,
    dims: IntArray,
    cell: float,
    starts: IntArray,
    xy: FloatArray,
    order: IntArray,
    lines: FloatArray,
    rot: FloatArray,
    px: float,
    py: float,
    gate: float,
    cauchy: float,
    inv_var: float,
    idx: IntArray,
    jac: FloatArray,
    res: FloatArray,
    w: FloatArray,
    wj: FloatArray,
) -> int:
    """Every rotated point's correspondence in ``idx``; the terms of the matched ones, or -1 when one is ambiguous.

    ``idx`` receives the target index within the gate, :data:`NONE` or
    :data:`AMBIGUOUS`; only when no query is ambiguous are the terms written
    (:func:`terms`) and their count returned.
    """
    gate2 = gate * gate
    ambiguous = False
    for i in range(rot.shape[0]):
        at, unsure = _nearest_one(origin, dims, cell, starts, xy, rot[i, 0] + px, rot[i, 1] + py, gate2)
        if unsure:
            idx[i] = -2
            ambiguous = True
        else:
            idx[i] = order[at] if at >= 0 else -1
    if ambiguous:
        return -1
    return _terms(lines, rot, px, py, cauchy, inv_var, idx, jac, res, w, wj)


@jitable
def _terms(
    lines: FloatArray,
    rot: FloatArray,
    px: float,
    py: float,
    cauchy: float,
    inv_var: float,
    idx: IntArray,
    jac: FloatArray,
    res: FloatArray,
    w: FloatArray,
    wj: FloatArray,
) -> int:
    """Residual, Jacobian row, Cauchy weight and weighted row of each matched point, in order; their count.

    The operations of the numpy formulation they replace, in its order:
    ``moved = rot + t``, ``diff = moved - p``, ``res = n0 * d0 + n1 * d1``,
    ``jac = (n0, n1, n1 * r0 - n0 * r1)``, ``w = 1 / (1 + (res / c) ** 2)``,
    ``wj = jac * (w * inv_var)``.
    """
    m = 0
    for i in range(idx.shape[0]):
        j = idx[i]
        if j < 0:
            continue
        r0, r1 = rot[i, 0], rot[i, 1]
        n0, n1 = lines[j, 2], lines[j, 3]
        d0 = (r0 + px) - lines[j, 0]
        d1 = (r1 + py) - lines[j, 1]
        e = n0 * d0 + n1 * d1
        res[m] = e
        jac[m, 0] = n0
        jac[m, 1] = n1
        jac[m, 2] = n1 * r0 - n0 * r1
        s = e / cauchy
        w[m] = 1.0 / (1.0 + s * s)
        scale = w[m] * inv_var
        wj[m, 0] = jac[m, 0] * scale
        wj[m, 1] = jac[m, 1] * scale
        wj[m, 2] = jac[m, 2] * scale
        m += 1
    return m


@kernel
def terms(
    lines: FloatArray,
    rot: FloatArray,
    px: float,
    py: float,
    cauchy: float,
    inv_var: float,
    idx: IntArray,
    jac: FloatArray,
    res: FloatArray,
    w: FloatArray,
    wj: FloatArray,
) -> int:
    """:func:`_terms` called from Python (after the ambiguous queries were answered by the k-d tree)."""
    return _terms(lines, rot, px, py, cauchy, inv_var, idx, jac, res, w, wj)


class Matches:
    """One registration's correspondences and terms: buffers for ``n`` source points, filled once per ICP iteration.

    :meth:`find` returns views of the first rows (the matched points, in
    source order); they hold until the next call.
    """

    def __init__(self, n: int) -> None:
        self.idx: IntArray = np.empty(n, dtype=np.int64)
        self.jac: FloatArray = np.empty((n, 3))
        self.res: FloatArray = np.empty(n)
        self.w: FloatArray = np.empty(n)
        self.wj: FloatArray = np.empty((n, 3))

    def find(
        self,
        grid: Grid,
        tree: Callable[[], Any],
        lines: FloatArray,
        rot: FloatArray,
        pose: FloatArray,
        gate: float,
        cauchy: float,
        inv_var: float,
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Jacobian rows, residuals, Cauchy weights and weighted rows of the points of ``rot`` moved by ``pose``.

        The points kept are those ``tree().query(rot + pose[:2], k=1,
        distance_upper_bound=gate)`` finds with ``dist < gate`` (``tree()``
        gives the target's ``cKDTree``, asked only about ambiguous queries),
        their correspondences the same, and the terms the same bit for bit.
        """
        check_gate(gate)
        px, py = float(pose[0]), float(pose[1])
        idx, jac, res, w, wj = self.idx, self.jac, self.res, self.w, self.wj
        m = linearise_terms(
            grid.origin, grid.dims, grid.cell, grid.starts, grid.xy, grid.order, lines, rot, px, py, gate, cauchy,
            inv_var, idx, jac, res, w, wj,
        )  # fmt: skip
        if m < 0:
            self.ask_tree(tree(), rot, pose[:2], gate)
            m = terms(lines, rot, px, py, cauchy, inv_var, idx, jac, res, w, wj)
        return jac[:m], res[:m], w[:m], wj[:m]

    def ask_tree(self, tree: Any, rot: FloatArray, position: FloatArray, gate: float) -> None:
        """The k-d tree's answers in ``idx`` for the queries the grid search marked :data:`AMBIGUOUS`."""
        unsure = (self.idx == AMBIGUOUS).nonzero()[0]
        dist, found = tree.query(rot[unsure] + position, k=1, distance_upper_bound=gate)
        self.idx[unsure] = np.where(dist < gate, found, NONE)


def check_gate(gate: float) -> None:
    """Raise :class:`RegistrationError` unless the correspondence gate is finite and positive."""
    if not (math.isfinite(gate) and gate > 0):
        raise RegistrationError(f"grid search: expected a finite positive correspondence gate, got {gate}")


def _sample() -> tuple[FloatArray, FloatArray, FloatArray]:
    """Target points and normals and source points whose match meets every case: matched, unmatched, ambiguous.

    The first source point is equidistant from the first two target points
    (an exact tie, left to the k-d tree), so :func:`terms` is called too.
    """
    points = np.array([[0.0, 0.0], [0.2, 0.0], [0.4, 0.0], [5.0, 5.0]])
    normals = np.tile([0.0, 1.0], (len(points), 1))
    source = np.array([[0.1, 0.05], [0.4, 0.01], [3.0, -3.0]])
    return points, normals, source


def sample_calls() -> list[tuple[str, Callable[..., Any], tuple[Any, ...]]]:
    """``(kernel name, kernel, arguments)`` of each kernel, typed as :meth:`Matches.find` calls them on :func:`_sample`.

    What the wheel's kernel bundle is built from and checked against
    (``albot1.methods.kernel_sources``, :mod:`albot1.methods.albot1.kernel_bundle`):
    numba keys a cached kernel by its argument types, so these must be the
    types of a run's calls (a test checks that the warm-up then compiles
    nothing). The grid is built by :func:`build_grid` as written, so making
    the samples compiles nothing.
    """
    points, normals, source = _sample()
    pts = np.ascontiguousarray(points, dtype=np.float64)
    origin, dims, cell, starts, order = compiled.as_written(build_grid)(pts, CELL_M, MAX_CELLS_PER_POINT)
    xy = np.ascontiguousarray(pts[order])
    lines, rot = np.hstack([points, normals]), source @ np.eye(2)
    n = len(source)
    idx = np.zeros(n, dtype=np.int64)  # every point matched to the first target point: terms has rows to write
    buffers = (np.empty((n, 3)), np.empty(n), np.empty(n), np.empty((n, 3)))
    return [
        ("gtsam_graph.build_grid", build_grid, (pts, CELL_M, MAX_CELLS_PER_POINT)),
        (
            "gtsam_graph.linearise_terms",
            linearise_terms,
            (origin, dims, float(cell), starts, xy, order, lines, rot, 0.0, 0.0, 1.0, 0.1, 1.0, idx.copy(), *buffers),
        ),
        ("gtsam_graph.terms", terms, (lines, rot, 0.0, 0.0, 0.1, 1.0, idx, *buffers)),
    ]


def warm_up(announce: Callable[[str], None] | None = None) -> None:
    """Compile the kernels (or load them from numba's cache) before a run's first scan, with the run's argument types.

    Cold kernels are first sought in the wheel's kernel bundle, by Albot1's
    own loader with its checks (:func:`kernel_bundle.seed`; nothing happens
    outside a wheel or where the bundle does not fit). ``announce`` receives a
    line before and after a real compilation (none for a cache load), as
    Albot1's warm-up does.
    """
    from scipy.spatial import cKDTree

    def run() -> None:
        points, normals, source = _sample()
        lines = np.hstack([points, normals])
        Matches(len(source)).find(
            Grid(points), lambda: cKDTree(points), lines, source @ np.eye(2), np.zeros(3), 1.0, 0.1, 1.0
        )

    warm_kernels((build_grid, linearise_terms, terms), sample_calls, "grid search", announce, run)
