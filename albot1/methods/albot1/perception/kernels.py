"""The per-scan loops of Albot1's perception: view construction and landmark recognition.

Every function here is plain Python over numpy arrays and scalars in the
subset numba compiles. :mod:`albot1.methods.albot1.perception.accel` hands out
either the jitted or the interpreted version of the same source, so the
accelerated path can never drift from the readable one (tests run both on
the same inputs). Geometry is in the thesis frame (robot at the origin facing
+y); endpoint labels are those of
:mod:`albot1.methods.albot1.perception.endpoints`.

Distances use ``np.hypot``, not ``math.hypot``: numba compiles both to C's
``hypot``, while CPython's ``math.hypot`` is its own, more accurate routine
that differs in the last bit for about 0.6 % of inputs, which would make the
interpreted kernels disagree with the compiled ones.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import wrap_angle
from albot1.methods.albot1.perception.endpoints import CORNER, OCCLUDED, OCCLUDING, UNSTABLE, is_stable

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def build_view(
    ranges: FloatArray,
    angles: FloatArray,
    max_range: float,
    cluster_gap: float,
    cluster_size: float,
    break_point_height: float,
    surface_length: float,
    corner_min_turn: float,
    occlusion_margin: float,
    continuation_tolerance: float,
) -> tuple[FloatArray, IntArray, IntArray, IntArray]:
    """Thesis 3.1.3 steps 1-5 plus endpoint classification (3.1.4) for one scan.

    ``ranges``/``angles`` are in *thesis order* (left to right, i.e. beam
    angle descending). Returns ``surfaces (m, 4)`` (x1, y1, x2, y2, thesis
    frame, left to right), ``kinds (m, 2)`` (endpoint codes), ``beams (m, 2)``
    (thesis-order beam index of each endpoint) and ``cluster (m,)``.
    """
    n = ranges.shape[0]
    px = np.empty(n)
    py = np.empty(n)
    beam = np.empty(n, dtype=np.int64)
    k = 0
    for i in range(n):
        r = ranges[i]
        # Step 1, point filtering: no return (NaN), non-positive or beyond max_range.
        if r == r and r > 0.0 and r <= max_range:
            px[k] = -r * math.sin(angles[i])
            py[k] = r * math.cos(angles[i])
            beam[k] = i
            k += 1
    out_s = np.empty((max(k, 1), 4))
    out_k = np.zeros((max(k, 1), 2), dtype=np.int64)
    out_b = np.zeros((max(k, 1), 2), dtype=np.int64)
    out_c = np.zeros(max(k, 1), dtype=np.int64)
    if k == 0:
        return out_s[:0], out_k[:0], out_b[:0], out_c[:0]
    # Step 2, clustering of consecutive remaining points by Euclidean gap.
    starts = np.empty(k + 1, dtype=np.int64)
    nc = 0
    starts[nc] = 0
    nc += 1
    for i in range(1, k):
        if np.hypot(px[i] - px[i - 1], py[i] - py[i - 1]) > cluster_gap:
            starts[nc] = i
            nc += 1
    starts[nc] = k
    # Step 3, recursive splitting; pieces come out left to right.
    piece_a = np.empty(2 * k + 2, dtype=np.int64)
    piece_b = np.empty(2 * k + 2, dtype=np.int64)
    piece_c = np.empty(2 * k + 2, dtype=np.int64)
    npieces = 0
    stack_a = np.empty(2 * k + 2, dtype=np.int64)
    stack_b = np.empty(2 * k + 2, dtype=np.int64)
    for c in range(nc):
        stack_a[0] = starts[c]
        stack_b[0] = starts[c + 1] - 1
        top = 1
        while top > 0:
            top -= 1
            i0 = stack_a[top]
            i1 = stack_b[top]
            dx = px[i1] - px[i0]
            dy = py[i1] - py[i0]
            chord = np.hypot(dx, dy)
            split = -1
            if chord > cluster_size and i1 - i0 >= 2:
                best = break_point_height
                for j in range(i0 + 1, i1):
                    h = abs(dx * (py[j] - py[i0]) - dy * (px[j] - px[i0])) / chord
                    if h > best:
                        best = h
                        split = j
            if split >= 0:
                # Push the right half first so the left half is finished first.
                stack_a[top] = split
                stack_b[top] = i1
                top += 1
                stack_a[top] = i0
                stack_b[top] = split
                top += 1
            else:
                piece_a[npieces] = i0
                piece_b[npieces] = i1
                piece_c[npieces] = c
                npieces += 1
    # Steps 4-5, surface forming and filtering, with endpoint kinds.
    m = 0
    for p in range(npieces):
        i0 = piece_a[p]
        i1 = piece_b[p]
        length = np.hypot(px[i1] - px[i0], py[i1] - py[i0])
        if length < surface_length:
            continue
        c = piece_c[p]
        out_s[m, 0] = px[i0]
        out_s[m, 1] = py[i0]
        out_s[m, 2] = px[i1]
        out_s[m, 3] = py[i1]
        out_b[m, 0] = beam[i0]
        out_b[m, 1] = beam[i1]
        out_c[m] = c
        # P1: a cluster start looks left for occlusion, an inner split point is a corner or a bend.
        if i0 == starts[c]:
            out_k[m, 0] = _occlusion(
                ranges, angles, beam[i0], -1, occlusion_margin, px[i1], py[i1], continuation_tolerance
            )
        else:
            q0 = piece_a[p - 1]
            out_k[m, 0] = _corner(px, py, q0, i0, i1, corner_min_turn)
        if i1 == starts[c + 1] - 1:
            out_k[m, 1] = _occlusion(
                ranges, angles, beam[i1], 1, occlusion_margin, px[i0], py[i0], continuation_tolerance
            )
        else:
            q1 = piece_b[p + 1]
            out_k[m, 1] = _corner(px, py, i0, i1, q1, corner_min_turn)
        m += 1
    return out_s[:m], out_k[:m], out_b[:m], out_c[:m]


def _occlusion(
    ranges: FloatArray, angles: FloatArray, b: int, step: int, margin: float, ox: float, oy: float, tolerance: float
) -> int:
    """Kind of a cluster-boundary endpoint on beam ``b`` looking outward by ``step``.

    Occluding when the next beam with any return (max_range not applied:
    a far return is still background) is farther than this one by more than
    ``margin`` and does not lie on this surface's own line continued (within
    ``tolerance``; such a gap is the beams thinning out along a wall seen at
    a grazing angle, and the "edge" would travel with the robot). Occluded
    when it is nearer; unstable when there is no such beam before the edge
    of the field of view (the true edge is unseen). ``(ox, oy)`` is the
    surface's other endpoint.
    """
    n = ranges.shape[0]
    j = b + step
    while 0 <= j < n:
        r = ranges[j]
        if r == r and r > 0.0:
            if r <= ranges[b] + margin:
                return OCCLUDED
            if tolerance > 0.0:
                ex = -ranges[b] * math.sin(angles[b])
                ey = ranges[b] * math.cos(angles[b])
                qx = -r * math.sin(angles[j])
                qy = r * math.cos(angles[j])
                lx = ex - ox
                ly = ey - oy
                ll = np.hypot(lx, ly)
                if ll > 0.0 and abs(lx * (qy - oy) - ly * (qx - ox)) / ll <= tolerance:
                    return UNSTABLE
            return OCCLUDING
        j += step
    return UNSTABLE


def _corner(px: FloatArray, py: FloatArray, a: int, b: int, c: int, min_turn: float) -> int:
    """CORNER when the pieces a->b and b->c turn by at least ``min_turn`` radians at b."""
    ux = px[b] - px[a]
    uy = py[b] - py[a]
    vx = px[c] - px[b]
    vy = py[c] - py[b]
    if (ux == 0.0 and uy == 0.0) or (vx == 0.0 and vy == 0.0):
        return UNSTABLE
    turn = abs(math.atan2(ux * vy - uy * vx, ux * vx + uy * vy))
    if turn >= min_turn:
        return CORNER
    return UNSTABLE


def recognise_landmarks(
    prev: FloatArray,
    prev_kinds: IntArray,
    cur: FloatArray,
    cur_kinds: IntArray,
    xr: float,
    yr: float,
    theta: float,
    max_angle: float,
    max_distance: float,
    greedy: bool,
) -> tuple[IntArray, IntArray, IntArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Algorithm 1 on arrays: predict (eqs 3.3-3.4), test every pair, pick the matches.

    ``(xr, yr, theta)`` is the current robot in the previous view (eqs
    3.1-3.2 or the exact increment). A pair passes when the directions
    (P1->P2) differ by less than ``max_angle`` and a same-side endpoint that
    is stable (occluding or corner) in both views moved less than
    ``max_distance``; the smaller such gap is the pair's gap. ``greedy``
    pairs one-to-one by smallest gap; otherwise the nested loop's
    last-writer-wins per current landmark. Returns, ordered by current
    index, ``(i, j, side, gap, angle_diff, d_prev, d_prev_current)``: the
    last two are the distance of the matched previous endpoint from the
    robot in the previous view and predicted into the current one.
    """
    p = prev.shape[0]
    q = cur.shape[0]
    c = math.cos(theta)
    s = math.sin(theta)
    pred = np.empty((p, 4))
    for i in range(p):
        for e in range(2):
            dx = prev[i, 2 * e] - xr
            dy = prev[i, 2 * e + 1] - yr
            pred[i, 2 * e] = dx * c + dy * s
            pred[i, 2 * e + 1] = dy * c - dx * s
    ii = np.empty(p * q, dtype=np.int64)
    jj = np.empty(p * q, dtype=np.int64)
    ss = np.empty(p * q, dtype=np.int64)
    gg = np.empty(p * q)
    aa = np.empty(p * q)
    cur_dir = np.empty(q)
    for j in range(q):
        cur_dir[j] = math.atan2(cur[j, 3] - cur[j, 1], cur[j, 2] - cur[j, 0])
    n = 0
    for i in range(p):
        ai = math.atan2(pred[i, 3] - pred[i, 1], pred[i, 2] - pred[i, 0])
        for j in range(q):
            da = abs(wrap_angle(cur_dir[j] - ai))
            if da >= max_angle:
                continue
            best = max_distance
            side = -1
            for e in range(2):
                if is_stable(prev_kinds[i, e]) and is_stable(cur_kinds[j, e]):
                    g = np.hypot(pred[i, 2 * e] - cur[j, 2 * e], pred[i, 2 * e + 1] - cur[j, 2 * e + 1])
                    if g < best:
                        best = g
                        side = e
            if side >= 0:
                ii[n] = i
                jj[n] = j
                ss[n] = side
                gg[n] = best
                aa[n] = da
                n += 1
    # owner[j]: the pair that labels current landmark j (-1: unrecognised).
    owner = np.full(q, -1, dtype=np.int64)
    if greedy:
        used = np.zeros(p, dtype=np.bool_)
        order = np.argsort(gg[:n], kind="mergesort")
        for o in order:
            if used[ii[o]] or owner[jj[o]] >= 0:
                continue
            used[ii[o]] = True
            owner[jj[o]] = o
    else:
        for o in range(n):
            owner[jj[o]] = o
    m = 0
    for j in range(q):
        if owner[j] >= 0:
            m += 1
    oi = np.empty(m, dtype=np.int64)
    oj = np.empty(m, dtype=np.int64)
    os_ = np.empty(m, dtype=np.int64)
    og = np.empty(m)
    oa = np.empty(m)
    od = np.empty(m)
    odc = np.empty(m)
    k = 0
    for j in range(q):
        o = owner[j]
        if o < 0:
            continue
        i = ii[o]
        e = ss[o]
        oi[k] = i
        oj[k] = j
        os_[k] = e
        og[k] = gg[o]
        oa[k] = aa[o]
        od[k] = np.hypot(prev[i, 2 * e], prev[i, 2 * e + 1])
        odc[k] = np.hypot(pred[i, 2 * e], pred[i, 2 * e + 1])
        k += 1
    return oi, oj, os_, og, oa, od, odc
