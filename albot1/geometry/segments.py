"""Line-segment geometry: distances, crossing tests and moving segments between frames.

A segment is ``(x1, y1, x2, y2)``. The scalar functions here are written in
the subset of Python that numba compiles (plain floats, indexing, :mod:`math`)
because the Albot1 kernels call them from compiled loops; they run unchanged
in CPython (:mod:`albot1.methods.albot1.jit` compiles them together with
their callers). :func:`transform_segments` is ordinary numpy.

Distances use ``np.hypot``, not ``math.hypot``: numba compiles both to C's
``hypot``, while CPython's ``math.hypot`` is its own, more accurate routine
that differs in the last bit for about 0.6 % of inputs, which would make the
interpreted kernels disagree with the compiled ones.
"""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry.se2 import PoseLike
from albot1.geometry.types import FloatArray


def orientation(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> float:
    """Twice the signed area of triangle a, b, c: positive when c is left of a->b, 0 when collinear."""
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


def closest_parameter(x: float, y: float, ax: float, ay: float, bx: float, by: float) -> float:
    """Where the point of segment a-b nearest (x, y) lies: the fraction ``t`` from a, clipped to ``[0, 1]``.

    A degenerate segment (a = b) gives 0.
    """
    ex = bx - ax
    ey = by - ay
    l2 = ex * ex + ey * ey
    if l2 > 0.0:
        return clip_parameter((x - ax) * ex + (y - ay) * ey, l2)
    return 0.0


def clip_parameter(along: float, l2: float) -> float:
    """:func:`closest_parameter` from the projection ``along`` (``(p - a) . (b - a)``) and ``l2 = |b - a|^2 > 0``.

    Its own function so that a kernel which has ``along`` already (the overlap rule's test, Albot1+'s nearest
    surface) clips it with the same arithmetic, and the same bits, without computing it twice.
    """
    return min(1.0, max(0.0, along / l2))


def point_segment_distance(x: float, y: float, s: FloatArray) -> float:
    """Distance from the point (x, y) to segment ``s``."""
    t = closest_parameter(x, y, s[0], s[1], s[2], s[3])
    distance: float = np.hypot(s[0] + t * (s[2] - s[0]) - x, s[1] + t * (s[3] - s[1]) - y)
    return distance


def line_angle(direction_difference: float) -> float:
    """The angle between two undirected lines whose directions differ by ``direction_difference``, in [0, pi/2].

    Folds by the floored modulo of :func:`albot1.geometry.se2.wrap_angle`, on half turns.
    """
    return abs((direction_difference + 0.5 * math.pi) % math.pi - 0.5 * math.pi)


def segments_cross(a: FloatArray, b: FloatArray) -> bool:
    """Whether segments ``a`` and ``b`` cross.

    ``a``'s endpoints must lie strictly on opposite sides of ``b``'s line and
    ``b``'s endpoints on different sides of ``a``'s line by the sign test
    ``> 0`` (so collinear segments never cross).
    """
    d1 = orientation(b[0], b[1], b[2], b[3], a[0], a[1])
    d2 = orientation(b[0], b[1], b[2], b[3], a[2], a[3])
    d3 = orientation(a[0], a[1], a[2], a[3], b[0], b[1])
    d4 = orientation(a[0], a[1], a[2], a[3], b[2], b[3])
    return ((d1 > 0.0) != (d2 > 0.0)) and ((d3 > 0.0) != (d4 > 0.0)) and d1 != 0.0 and d2 != 0.0


def segment_distance(a: FloatArray, b: FloatArray) -> float:
    """Smallest distance between segments ``a`` and ``b``; 0 if they cross."""
    if segments_cross(a, b):
        return 0.0
    d = point_segment_distance(a[0], a[1], b)
    d = min(d, point_segment_distance(a[2], a[3], b))
    d = min(d, point_segment_distance(b[0], b[1], a))
    return min(d, point_segment_distance(b[2], b[3], a))


def transform_segments(pose: PoseLike, segments: FloatArray) -> FloatArray:
    """Segments ``(m, 4)`` from a frame into its parent frame, given that frame's ``pose`` there."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    seg = np.asarray(segments, dtype=float).reshape(-1, 4)
    out = np.empty_like(seg)
    out[:, 0] = pose[0] + c * seg[:, 0] - s * seg[:, 1]
    out[:, 1] = pose[1] + s * seg[:, 0] + c * seg[:, 1]
    out[:, 2] = pose[0] + c * seg[:, 2] - s * seg[:, 3]
    out[:, 3] = pose[1] + s * seg[:, 2] + c * seg[:, 3]
    return out
