"""The per-scan loops of Albot1's map update and of the perceptual map's grid index.

Plain Python over numpy arrays and scalars in the subset numba compiles;
numba compiles them (:mod:`albot1.methods.albot1.compiled`) and
:class:`~albot1.methods.albot1.mapping.kernel_set.MappingKernels` hands out
the compiled or the Python version of the same source (tests run both on the
same inputs). The whole update of one view is in
:mod:`albot1.methods.albot1.mapping.update_kernels`. Segment geometry comes from
:mod:`albot1.geometry.segments`, compiled into these loops.

Distances use ``np.hypot``, not ``math.hypot``: numba compiles both to C's
``hypot``, while CPython's ``math.hypot`` is its own, more accurate routine
that differs in the last bit for about 0.6 % of inputs, which would make the
interpreted kernels disagree with the compiled ones.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.segments import closest_parameter, line_angle, segment_distance
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import falses, jitable, kernel

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@jitable
def polygon_points(view: FloatArray, x: float, y: float, with_robot: bool) -> FloatArray:
    """Algorithm 3 line 7: the robot ``(x, y)`` if ``with_robot``, then each surface's P1, P2 (see ``view_polygon``)."""
    first = 1 if with_robot else 0
    poly = np.empty((first + 2 * view.shape[0], 2))
    if with_robot:
        poly[0, 0] = x
        poly[0, 1] = y
    for j in range(view.shape[0]):
        poly[first + 2 * j, 0] = view[j, 0]
        poly[first + 2 * j, 1] = view[j, 1]
        poly[first + 2 * j + 1, 0] = view[j, 2]
        poly[first + 2 * j + 1, 1] = view[j, 3]
    return poly


@jitable
def covered(poly: FloatArray, view: FloatArray, x: float, y: float, margin: float, surfaces_only: bool) -> bool:
    """Whether the point ``(x, y)`` is inside the closed polygon (even-odd) or within ``margin`` of it.

    ``poly`` is ``(v, 2)`` (implicitly closed); the view polygon is
    star-shaped around the robot, so even-odd is its exact interior. With
    ``surfaces_only`` the margin is measured from the view's surfaces
    (``view`` ``(m, 4)``), perpendicular to each and within its extent, not
    from the polygon's sides through unperceived space (field-of-view edges,
    gaps); otherwise from every polygon edge. A scalar function, so the
    bisection of :func:`clip_parameter` allocates nothing per probe.
    """
    v = poly.shape[0]
    m2 = margin * margin
    inside = False
    near = False
    for e in range(v):
        ax = poly[e, 0]
        ay = poly[e, 1]
        if e + 1 < v:
            bx = poly[e + 1, 0]
            by = poly[e + 1, 1]
        else:
            bx = poly[0, 0]
            by = poly[0, 1]
        if (ay > y) != (by > y):
            xc = ax + (y - ay) * (bx - ax) / (by - ay)
            if x < xc:
                inside = not inside
        if not near and not surfaces_only:
            t = closest_parameter(x, y, ax, ay, bx, by)
            dx = ax + t * (bx - ax) - x
            dy = ay + t * (by - ay) - y
            if dx * dx + dy * dy < m2:
                near = True
    if surfaces_only and not inside:
        for j in range(view.shape[0]):
            ex = view[j, 2] - view[j, 0]
            ey = view[j, 3] - view[j, 1]
            l2 = ex * ex + ey * ey
            if l2 <= 0.0:
                continue
            t = ((x - view[j, 0]) * ex + (y - view[j, 1]) * ey) / l2
            if t < 0.0 or t > 1.0:
                continue
            dx = view[j, 0] + t * ex - x
            dy = view[j, 1] + t * ey - y
            if dx * dx + dy * dy < m2:
                near = True
                break
    return inside or near


@kernel
def classify_endpoints(
    poly: FloatArray, view: FloatArray, pts: FloatArray, margin: float, surfaces_only: bool
) -> BoolArray:
    """For each point ``(n, 2)``: inside the view polygon or within ``margin`` of it (:func:`covered`)."""
    out = falses(pts.shape[0])
    for k in range(pts.shape[0]):
        out[k] = covered(poly, view, pts[k, 0], pts[k, 1], margin, surfaces_only)
    return out


@jitable
def view_angles(view: FloatArray) -> FloatArray:
    """Direction (P1 -> P2, radians) of each view surface ``(m, 4)``."""
    out = np.empty(view.shape[0])
    for j in range(view.shape[0]):
        out[j] = math.atan2(view[j, 3] - view[j, 1], view[j, 2] - view[j, 0])
    return out


@jitable
def closest_parallel(
    seg: FloatArray, view: FloatArray, angles: FloatArray, taken: BoolArray, max_angle: float, max_distance: float
) -> int:
    """:func:`best_correspondence` given the view's :func:`view_angles` (computed once per update)."""
    best = -1
    best_d = max_distance
    a0 = math.atan2(seg[3] - seg[1], seg[2] - seg[0])
    for j in range(view.shape[0]):
        if taken[j]:
            continue
        da = line_angle(angles[j] - a0)
        if da >= max_angle:
            continue
        d = segment_distance(seg, view[j])
        if d < best_d:
            best = j
            best_d = d
    return best


@kernel
def best_correspondence(
    seg: FloatArray, view: FloatArray, taken: BoolArray, max_angle: float, max_distance: float
) -> int:
    """Index of the free view surface closest to ``seg`` (segment distance) among those parallel
    to it within ``max_angle`` (undirected) and nearer than ``max_distance``; -1 if none."""
    return closest_parallel(seg, view, view_angles(view), taken, max_angle, max_distance)


@kernel
def clip_parameter(
    poly: FloatArray, view: FloatArray, x0: float, y0: float, x1: float, y1: float, margin: float, surfaces_only: bool
) -> float:
    """Fraction ``t`` along (x0, y0)->(x1, y1) where the segment first enters the covered region.

    (x0, y0) is outside, (x1, y1) covered (:func:`classify_endpoints`);
    bisection on that predicate (the grown region has no closed form without
    a buffer operation), to 1e-4 of the segment.
    """
    lo = 0.0
    hi = 1.0
    for _ in range(14):
        mid = 0.5 * (lo + hi)
        if covered(poly, view, x0 + mid * (x1 - x0), y0 + mid * (y1 - y0), margin, surfaces_only):
            hi = mid
        else:
            lo = mid
    return lo


@kernel
def place_segments(segments: FloatArray, x: float, y: float, c: float, s: float) -> FloatArray:
    """Segments ``(m, 4)`` placed at ``(x, y)``, heading cosine/sine ``c``/``s``: ``transform_segments``'s
    arithmetic operation for operation, one call instead of a dozen numpy ones (the tests compare the bits)."""
    out = np.empty((segments.shape[0], 4))
    for i in range(segments.shape[0]):
        out[i, 0] = x + c * segments[i, 0] - s * segments[i, 1]
        out[i, 1] = y + s * segments[i, 0] + c * segments[i, 1]
        out[i, 2] = x + c * segments[i, 2] - s * segments[i, 3]
        out[i, 3] = y + s * segments[i, 2] + c * segments[i, 3]
    return out


#: Actions of :func:`resolve_partial` on a map surface with one end inside the view.
KEEP = 0
EXTENDED = 1
TRIMMED = 2
DELETED = 3


@kernel
def resolve_partial(
    segs: FloatArray,
    p1_inside: BoolArray,
    view: FloatArray,
    taken: BoolArray,
    poly: FloatArray,
    max_angle: float,
    max_distance: float,
    clip: bool,
    margin: float,
    surfaces_only: bool,
) -> tuple[IntArray, FloatArray, IntArray]:
    """Algorithm 3 lines 11-12 for every map surface with exactly one end inside the view, in order.

    For surface ``r`` (``segs[r]``, its P1 inside when ``p1_inside[r]``):
    the corresponding view surface is :func:`best_correspondence` among
    those not ``taken`` yet (it is then taken); the surface runs from its
    outside end to the far end of that view surface (seen from the outside
    end). Without one it is cut where it enters the covered region
    (:func:`clip_parameter`) when ``clip``, else kept. Returns per surface
    the action (:data:`KEEP`, :data:`EXTENDED` when longer, :data:`TRIMMED`
    when not, :data:`DELETED` when nothing is left), the new endpoints and
    the view surface it took (-1 if none). ``taken`` is not modified.
    """
    k = segs.shape[0]
    action = np.empty(k, dtype=np.int64)  # every row is written below
    new = np.empty((k, 4))
    match = np.empty(k, dtype=np.int64)
    for r in range(k):  # a loop, not np.full: one numpy routine less to compile
        match[r] = -1
    used = taken.copy()
    angles = view_angles(view)
    for r in range(k):
        seg = segs[r]
        if p1_inside[r]:
            ox = seg[2]
            oy = seg[3]
            ix = seg[0]
            iy = seg[1]
        else:
            ox = seg[0]
            oy = seg[1]
            ix = seg[2]
            iy = seg[3]
        best = closest_parallel(seg, view, angles, used, max_angle, max_distance)
        if best >= 0:
            v = view[best]
            if np.hypot(v[0] - ox, v[1] - oy) >= np.hypot(v[2] - ox, v[3] - oy):
                fx = v[0]
                fy = v[1]
            else:
                fx = v[2]
                fy = v[3]
            used[best] = True
            match[r] = best
        elif clip:
            t = clip_parameter(poly, view, ox, oy, ix, iy, margin, surfaces_only)
            fx = ox + t * (ix - ox)
            fy = oy + t * (iy - oy)
        else:
            action[r] = KEEP
            new[r, 0] = seg[0]
            new[r, 1] = seg[1]
            new[r, 2] = seg[2]
            new[r, 3] = seg[3]
            continue
        if p1_inside[r]:
            new[r, 0] = fx
            new[r, 1] = fy
            new[r, 2] = ox
            new[r, 3] = oy
        else:
            new[r, 0] = ox
            new[r, 1] = oy
            new[r, 2] = fx
            new[r, 3] = fy
        new_len = np.hypot(new[r, 2] - new[r, 0], new[r, 3] - new[r, 1])
        if new_len <= 1e-9:
            action[r] = DELETED
        elif new_len > np.hypot(seg[2] - seg[0], seg[3] - seg[1]):
            action[r] = EXTENDED
        else:
            action[r] = TRIMMED
    return action, new, match
