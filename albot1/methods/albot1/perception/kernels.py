"""The per-scan loops of Albot1's perception: view construction and landmark recognition.

Every function here is plain Python over numpy arrays and scalars in the
subset numba compiles (:mod:`albot1.methods.albot1.compiled`);
:class:`PerceptionKernels` hands out the compiled or the Python version of the same source, so the
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
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import falses, jitable, kernel, select
from albot1.methods.albot1.ordering import stable_order
from albot1.methods.albot1.perception.endpoints import CORNER, OCCLUDED, OCCLUDING, UNSTABLE, is_stable

IntArray = NDArray[np.int64]


@kernel
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
    end_spacing_max: float,
    grazing: float,
    fit_lines: bool,
) -> tuple[FloatArray, IntArray, IntArray, IntArray]:
    """Thesis 3.1.3 steps 1-5 plus endpoint classification (3.1.4) for one scan.

    ``ranges``/``angles`` are in *thesis order* (left to right, i.e. beam
    angle descending). Returns ``surfaces (m, 4)`` (x1, y1, x2, y2, thesis
    frame, left to right), ``kinds (m, 2)`` (endpoint codes), ``beams (m, 2)``
    (thesis-order beam index of each endpoint) and ``cluster (m,)``.

    ``end_spacing_max`` > 0 turns an occluding or corner end unstable when
    the next point on its own surface is farther from it than that: the
    beams are sparse there (a wall seen at a grazing angle), so the end is
    wherever the last beam happened to fall and moves with the robot.
    ``fit_lines`` replaces the chord (first to last point, the thesis's
    surface) by the total-least-squares line of the piece's points, ends
    projected onto it, and puts a point shared by two neighbouring pieces
    at the intersection of their lines (:func:`_fit_piece`,
    :func:`_join_corner`). Labels are decided on the raw points either way.
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
    # np.empty, not np.zeros (one numpy routine less to compile): every returned row is written below
    out_k = np.empty((max(k, 1), 2), dtype=np.int64)
    out_b = np.empty((max(k, 1), 2), dtype=np.int64)
    out_c = np.empty(max(k, 1), dtype=np.int64)
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
    # The fitted line of each output surface (centre and unit direction), for corner intersections.
    line = np.empty((max(npieces, 1), 4))
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
        if end_spacing_max > 0.0 and i1 > i0:
            if is_stable(out_k[m, 0]) and _sparse_end(
                px, py, ranges, angles, beam, i0, i0 + 1, end_spacing_max, grazing
            ):
                out_k[m, 0] = UNSTABLE
            if is_stable(out_k[m, 1]) and _sparse_end(
                px, py, ranges, angles, beam, i1, i1 - 1, end_spacing_max, grazing
            ):
                out_k[m, 1] = UNSTABLE
        if fit_lines:
            _fit_piece(px, py, i0, i1, i0 != starts[c], i1 != starts[c + 1] - 1, out_s, line, m)
            if m > 0 and out_c[m - 1] == c and out_b[m - 1, 1] == out_b[m, 0]:
                _join_corner(line, out_s, m, px[i0], py[i0])
        m += 1
    return out_s[:m], out_k[:m], out_b[:m], out_c[:m]


@jitable
def _sparse_end(
    px: FloatArray,
    py: FloatArray,
    ranges: FloatArray,
    angles: FloatArray,
    beam: IntArray,
    e: int,
    q: int,
    spacing_max: float,
    grazing: float,
) -> bool:
    """Whether the end point ``e`` lies too far from its neighbour ``q`` on the same surface to be a fixed edge.

    Sparse: farther than ``spacing_max``, and (with ``grazing`` > 0) farther
    than ``grazing`` times the spacing the same two beams would have on a
    surface facing the robot (range times the angle between them), i.e. the
    beams meet the surface at a grazing angle, beyond ``arccos(1 / grazing)``.
    """
    spacing: float = np.hypot(px[q] - px[e], py[q] - py[e])
    if spacing <= spacing_max:
        return False
    if grazing > 0.0:
        facing: float = ranges[beam[e]] * abs(angles[beam[q]] - angles[beam[e]])
        return spacing > grazing * facing
    return True


#: A point shared by two fitted lines moves to their intersection only if they turn by at least this (sine)...
TLS_CORNER_MIN_SINE = math.sin(math.radians(10.0))
#: ... and the intersection lies within this of the shared point (m); otherwise each end keeps its projection.
TLS_CORNER_MAX_SHIFT_M = 0.3


@jitable
def _fit_piece(
    px: FloatArray,
    py: FloatArray,
    i0: int,
    i1: int,
    shared_start: bool,
    shared_end: bool,
    out_s: FloatArray,
    line: FloatArray,
    m: int,
) -> None:
    """Surface ``m`` as the total-least-squares line of points ``i0..i1``, ends projected onto it.

    A point shared with the neighbouring piece (a split point) lies near
    the corner, on either wall; it is left out of the fit when at least
    three points remain. ``line[m]`` gets the line's centre and unit
    direction (P1 to P2).
    """
    a0 = i0 + 1 if shared_start and i1 - i0 >= 3 else i0
    a1 = i1 - 1 if shared_end and i1 - a0 >= 3 else i1
    count = a1 - a0 + 1
    mx = 0.0
    my = 0.0
    for j in range(a0, a1 + 1):
        mx += px[j]
        my += py[j]
    mx /= count
    my /= count
    sxx = 0.0
    syy = 0.0
    sxy = 0.0
    for j in range(a0, a1 + 1):
        dx = px[j] - mx
        dy = py[j] - my
        sxx += dx * dx
        syy += dy * dy
        sxy += dx * dy
    # The principal axis of the scatter (the direction minimising the summed squared distances to the line).
    theta = 0.5 * math.atan2(2.0 * sxy, sxx - syy)
    ux = math.cos(theta)
    uy = math.sin(theta)
    if ux * (px[i1] - px[i0]) + uy * (py[i1] - py[i0]) < 0.0:
        ux = -ux
        uy = -uy
    t0 = (px[i0] - mx) * ux + (py[i0] - my) * uy
    t1 = (px[i1] - mx) * ux + (py[i1] - my) * uy
    out_s[m, 0] = mx + t0 * ux
    out_s[m, 1] = my + t0 * uy
    out_s[m, 2] = mx + t1 * ux
    out_s[m, 3] = my + t1 * uy
    line[m, 0] = mx
    line[m, 1] = my
    line[m, 2] = ux
    line[m, 3] = uy


@jitable
def _join_corner(line: FloatArray, out_s: FloatArray, m: int, sx: float, sy: float) -> None:
    """Put the point shared by surfaces ``m - 1`` and ``m`` (raw position ``sx, sy``) where their lines cross.

    Only when the lines turn by at least :data:`TLS_CORNER_MIN_SINE` and the
    crossing is within :data:`TLS_CORNER_MAX_SHIFT_M` of the shared point:
    nearly parallel lines cross far away or nowhere.
    """
    vx = line[m - 1, 2]
    vy = line[m - 1, 3]
    ux = line[m, 2]
    uy = line[m, 3]
    den = vx * uy - vy * ux
    if abs(den) < TLS_CORNER_MIN_SINE:
        return
    wx = line[m, 0] - line[m - 1, 0]
    wy = line[m, 1] - line[m - 1, 1]
    t = (wx * uy - wy * ux) / den
    qx = line[m - 1, 0] + t * vx
    qy = line[m - 1, 1] + t * vy
    if np.hypot(qx - sx, qy - sy) > TLS_CORNER_MAX_SHIFT_M:
        return
    out_s[m - 1, 2] = qx
    out_s[m - 1, 3] = qy
    out_s[m, 0] = qx
    out_s[m, 1] = qy


@jitable
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


@jitable
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


@kernel
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
    owner = np.empty(q, dtype=np.int64)
    for j in range(q):  # a loop, not np.full: one numpy routine less to compile
        owner[j] = -1
    if greedy:
        used = falses(p)
        order = stable_order(gg[:n])
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


@kernel
def landmark_rows(surfaces: FloatArray, kinds: IntArray, min_length: float) -> tuple[IntArray, FloatArray, IntArray]:
    """``findLandmark`` (3.1.4): rows at least ``min_length`` long with a stable end, their surfaces and labels."""
    keep = np.empty(surfaces.shape[0], dtype=np.int64)
    n = 0
    for i in range(surfaces.shape[0]):
        length = np.hypot(surfaces[i, 2] - surfaces[i, 0], surfaces[i, 3] - surfaces[i, 1])
        if length >= min_length and (is_stable(kinds[i, 0]) or is_stable(kinds[i, 1])):
            keep[n] = i
            n += 1
    rows = keep[:n].copy()
    return rows, surfaces[rows], kinds[rows]


class PerceptionKernels:
    """The perception kernels a mapper calls: each compiled, or its Python source when ``compiled`` is False."""

    def __init__(self, compiled: bool = True) -> None:
        self.compiled = compiled
        self.build_view = select(build_view, compiled)
        self.recognise_landmarks = select(recognise_landmarks, compiled)
        self.landmark_rows = select(landmark_rows, compiled)
