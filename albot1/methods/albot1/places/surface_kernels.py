"""The places layer's surface kernels: merging collinear pieces, and which surfaces of two sets are the same.

Numba kernels (:mod:`albot1.methods.albot1.compiled`), in the thesis frame.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import wrap_angle
from albot1.geometry.segments import point_segment_distance
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import falses, jitable, kernel
from albot1.methods.albot1.mapping.kernels import classify_endpoints
from albot1.methods.albot1.ordering import stable_order

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@kernel
def merge_collinear(surfaces: FloatArray, max_angle: float, max_offset: float, max_gap: float) -> FloatArray:
    """Pieces of one straight structure as one surface, longest pieces first.

    A surface joins a longer one when their directions differ by less than
    ``max_angle``, its midpoint is within ``max_offset`` of the longer one's
    line, and along that line it overlaps it or leaves a gap of at most
    ``max_gap``; the joined surface spans both along the longer one's line.
    """
    n = surfaces.shape[0]
    length = np.empty(n)
    longest_first = np.empty(n)  # -length in the loop: an array expression would be one more routine to compile
    for i in range(n):
        length[i] = np.hypot(surfaces[i, 2] - surfaces[i, 0], surfaces[i, 3] - surfaces[i, 1])
        longest_first[i] = -length[i]
    order = stable_order(longest_first)
    gx = np.empty(n)
    gy = np.empty(n)
    gux = np.empty(n)
    guy = np.empty(n)
    lo_t = np.empty(n)
    hi_t = np.empty(n)
    k = 0
    cos_max = math.cos(max_angle)
    for r in range(n):
        i = order[r]
        if length[i] <= 0.0:
            continue
        x1 = surfaces[i, 0]
        y1 = surfaces[i, 1]
        x2 = surfaces[i, 2]
        y2 = surfaces[i, 3]
        ux = (x2 - x1) / length[i]
        uy = (y2 - y1) / length[i]
        mx = 0.5 * (x1 + x2)
        my = 0.5 * (y1 + y2)
        joined = False
        for g in range(k):
            if ux * gux[g] + uy * guy[g] < cos_max:
                continue
            if abs(-guy[g] * (mx - gx[g]) + gux[g] * (my - gy[g])) > max_offset:
                continue
            t1 = (x1 - gx[g]) * gux[g] + (y1 - gy[g]) * guy[g]
            t2 = (x2 - gx[g]) * gux[g] + (y2 - gy[g]) * guy[g]
            lo = min(t1, t2)
            hi = max(t1, t2)
            if lo <= hi_t[g] + max_gap and hi >= lo_t[g] - max_gap:
                lo_t[g] = min(lo_t[g], lo)
                hi_t[g] = max(hi_t[g], hi)
                joined = True
                break
        if not joined:
            gx[k] = x1
            gy[k] = y1
            gux[k] = ux
            guy[k] = uy
            lo_t[k] = 0.0
            hi_t[k] = length[i]
            k += 1
    out = np.empty((k, 4))
    for g in range(k):
        out[g, 0] = gx[g] + lo_t[g] * gux[g]
        out[g, 1] = gy[g] + lo_t[g] * guy[g]
        out[g, 2] = gx[g] + hi_t[g] * gux[g]
        out[g, 3] = gy[g] + hi_t[g] * guy[g]
    return out


@jitable
def _extent(points: FloatArray, axis: int) -> tuple[float, float]:
    """``points[:, axis].min()`` and ``.max()`` (``NaN`` if any is ``NaN``), as loops: numba's array reductions
    cost about 0.6 s of a cold compile (``docs/albot1-mapper.md``, "Compile time")."""
    if points.shape[0] == 0:
        raise ValueError("zero-size array to reduction operation minimum which has no identity")
    lo = points[0, axis]
    hi = lo
    for v in range(1, points.shape[0]):
        x = points[v, axis]
        if x < lo or x != x:  # a NaN sticks: every comparison with it is False
            lo = x
        if x > hi or x != x:
            hi = x
    return lo, hi


@kernel
def colocated(
    segments: FloatArray,
    box: FloatArray,
    owner: IntArray,
    excluded: IntArray,
    poly: FloatArray,
    view: FloatArray,
    margin: float,
    surfaces_only: bool,
) -> IntArray:
    """Rows of ``segments`` (remembered places' structure in the map) the view ``view`` co-locates with.

    Algorithm 3's rule for a map surface: an end inside the view polygon
    ``poly`` or within ``margin`` (of the view's surfaces, or of every polygon
    edge; the chapter-3 kernel
    :func:`albot1.methods.albot1.mapping.kernels.classify_endpoints`).
    Rows of an ``excluded`` place, and those whose bounding box ``box``
    cannot meet the polygon's grown box, are skipped.
    """
    x0, x1 = _extent(poly, 0)
    y0, y1 = _extent(poly, 1)
    x0 -= margin
    x1 += margin
    y0 -= margin
    y1 += margin
    n = segments.shape[0]
    rows = np.empty(n, dtype=np.int64)
    k = 0
    for r in range(n):
        if box[r, 2] < x0 or box[r, 0] > x1 or box[r, 3] < y0 or box[r, 1] > y1:
            continue
        skip = False
        for e in range(excluded.shape[0]):
            if owner[r] == excluded[e]:
                skip = True
        if not skip:
            rows[k] = r
            k += 1
    pts = np.empty((2 * k, 2))
    for q in range(k):
        pts[2 * q, 0] = segments[rows[q], 0]
        pts[2 * q, 1] = segments[rows[q], 1]
        pts[2 * q + 1, 0] = segments[rows[q], 2]
        pts[2 * q + 1, 1] = segments[rows[q], 3]
    near = classify_endpoints(poly, view, pts, margin, surfaces_only)
    out = np.empty(k, dtype=np.int64)
    m = 0
    for q in range(k):
        if near[2 * q] or near[2 * q + 1]:
            out[m] = rows[q]
            m += 1
    return out[:m]


@kernel
def same_any(a: FloatArray, b: FloatArray, max_angle: float, max_gap: float) -> tuple[BoolArray, BoolArray]:
    """Which surfaces of ``a`` have a same surface in ``b``, and which of ``b`` in ``a``.

    The same: directions within ``max_angle`` and the smallest endpoint-to-
    segment distance both ways within ``max_gap`` (as
    :func:`albot1.methods.albot1.places.memory.same_surfaces`, without its
    ``len(a) x len(b)`` arrays: a long visit closed into a large place pairs
    thousands with thousands).
    """
    na = a.shape[0]
    nb = b.shape[0]
    a_has = falses(na)
    b_has = falses(nb)
    bx0 = np.empty(nb)
    bx1 = np.empty(nb)
    by0 = np.empty(nb)
    by1 = np.empty(nb)
    db = np.empty(nb)
    for j in range(nb):
        bx0[j] = min(b[j, 0], b[j, 2]) - max_gap
        bx1[j] = max(b[j, 0], b[j, 2]) + max_gap
        by0[j] = min(b[j, 1], b[j, 3]) - max_gap
        by1[j] = max(b[j, 1], b[j, 3]) + max_gap
        db[j] = math.atan2(b[j, 3] - b[j, 1], b[j, 2] - b[j, 0])
    for i in range(na):
        ax0 = min(a[i, 0], a[i, 2])
        ax1 = max(a[i, 0], a[i, 2])
        ay0 = min(a[i, 1], a[i, 3])
        ay1 = max(a[i, 1], a[i, 3])
        da = math.atan2(a[i, 3] - a[i, 1], a[i, 2] - a[i, 0])
        for j in range(nb):
            if ax1 < bx0[j] or ax0 > bx1[j] or ay1 < by0[j] or ay0 > by1[j]:
                continue
            if abs(wrap_angle(da - db[j])) >= max_angle:
                continue
            gap = min(
                min(point_segment_distance(a[i, 0], a[i, 1], b[j]), point_segment_distance(a[i, 2], a[i, 3], b[j])),
                min(point_segment_distance(b[j, 0], b[j, 1], a[i]), point_segment_distance(b[j, 2], b[j, 3], a[i])),
            )
            if gap <= max_gap:
                a_has[i] = True
                b_has[j] = True
    return a_has, b_has
