"""The per-scan loops of the places layer: exit detection in a view and the structural matcher.

Plain Python over numpy arrays and scalars in the subset numba compiles;
:mod:`albot1.methods.albot1.places.accel` hands out the jitted or the
interpreted version of the same source (the tests run both). Geometry is in
the thesis frame (robot at the origin facing +y, surfaces left to right);
endpoint labels are those of :mod:`albot1.methods.albot1.perception.endpoints`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import wrap_angle
from albot1.geometry.segments import closest_parameter, orientation, point_segment_distance
from albot1.methods.albot1.mapping.kernels import classify_endpoints
from albot1.methods.albot1.perception.endpoints import CORNER, OCCLUDING

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


def detect_exits(
    surfaces: FloatArray,
    kinds: IntArray,
    min_width: float,
    max_width: float,
    min_depth: float,
    max_distance: float,
    both_occluding: bool,
) -> tuple[IntArray, IntArray]:
    """Exit-like gaps of one view: pairs ``(i, j)``, the gap running from surface i's P2 to surface j's P1.

    A pair is a candidate when ``i < j`` (j to the right of i), both ends are
    occluding (or, without ``both_occluding``, one occluding and the other a
    corner), the gap is ``min_width``-``max_width`` wide with its midpoint
    within ``max_distance`` of the robot, and every surface between them in
    the view (what is seen *through* the gap) lies beyond the gap's line, on
    the far side from the robot, by at least ``min_depth``. Each end takes
    part in one exit at most: candidates are accepted narrowest first (the
    shortest gap is the exit, as in Yeap's exits).
    """
    m = surfaces.shape[0]
    ci = np.empty(m * m, dtype=np.int64)
    cj = np.empty(m * m, dtype=np.int64)
    cw = np.empty(m * m)
    n = 0
    for i in range(m):
        ka = kinds[i, 1]
        if ka != OCCLUDING and ka != CORNER:
            continue
        ax = surfaces[i, 2]
        ay = surfaces[i, 3]
        for j in range(i + 1, m):
            kb = kinds[j, 0]
            if kb != OCCLUDING and kb != CORNER:
                continue
            if both_occluding:
                if ka != OCCLUDING or kb != OCCLUDING:
                    continue
            elif ka != OCCLUDING and kb != OCCLUDING:
                continue
            bx = surfaces[j, 0]
            by = surfaces[j, 1]
            w = np.hypot(bx - ax, by - ay)
            if w < min_width or w > max_width:
                continue
            if np.hypot(0.5 * (ax + bx), 0.5 * (ay + by)) > max_distance:
                continue
            robot_side = orientation(ax, ay, bx, by, 0.0, 0.0)
            if robot_side == 0.0:
                continue
            ok = True
            for k in range(i + 1, j):
                for e in range(2):
                    side = orientation(ax, ay, bx, by, surfaces[k, 2 * e], surfaces[k, 2 * e + 1])
                    # beyond the line: the other side from the robot, by at least min_depth
                    if side * robot_side >= 0.0 or abs(side) / w < min_depth:
                        ok = False
                        break
                if not ok:
                    break
            if ok:
                ci[n] = i
                cj[n] = j
                cw[n] = w
                n += 1
    order = np.argsort(cw[:n], kind="mergesort")
    used_left = np.zeros(m, dtype=np.bool_)
    used_right = np.zeros(m, dtype=np.bool_)
    out_i = np.empty(n, dtype=np.int64)
    out_j = np.empty(n, dtype=np.int64)
    k = 0
    for r in range(n):
        c = order[r]
        if used_left[ci[c]] or used_right[cj[c]]:
            continue
        used_left[ci[c]] = True
        used_right[cj[c]] = True
        out_i[k] = ci[c]
        out_j[k] = cj[c]
        k += 1
    return out_i[:k], out_j[:k]


def merge_collinear(surfaces: FloatArray, max_angle: float, max_offset: float, max_gap: float) -> FloatArray:
    """Pieces of one straight structure as one surface, longest pieces first.

    A surface joins a longer one when their directions differ by less than
    ``max_angle``, its midpoint is within ``max_offset`` of the longer one's
    line, and along that line it overlaps it or leaves a gap of at most
    ``max_gap``; the joined surface spans both along the longer one's line.
    """
    n = surfaces.shape[0]
    length = np.empty(n)
    for i in range(n):
        length[i] = np.hypot(surfaces[i, 2] - surfaces[i, 0], surfaces[i, 3] - surfaces[i, 1])
    order = np.argsort(-length, kind="mergesort")
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


def seen_through(
    seg: FloatArray, ids: IntArray, crossable: BoolArray, ox: float, oy: float, points: FloatArray
) -> IntArray:
    """For each point: the id of the first crossable exit segment the line from (ox, oy) to it passes through.

    -1 where it passes through none; with several, the one met first along the line.
    """
    n = points.shape[0]
    out = np.full(n, -1, dtype=np.int64)
    for p in range(n):
        px = points[p, 0]
        py = points[p, 1]
        best = np.inf
        for r in range(seg.shape[0]):
            if not crossable[r]:
                continue
            ax = seg[r, 0]
            ay = seg[r, 1]
            bx = seg[r, 2]
            by = seg[r, 3]
            d1 = orientation(ax, ay, bx, by, ox, oy)
            d2 = orientation(ax, ay, bx, by, px, py)
            if d1 * d2 >= 0.0:
                continue
            d3 = orientation(ox, oy, px, py, ax, ay)
            d4 = orientation(ox, oy, px, py, bx, by)
            if d3 * d4 >= 0.0:
                continue
            along = d1 / (d1 - d2)
            if along < best:
                best = along
                out[p] = ids[r]
    return out


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
    x0 = poly[:, 0].min() - margin
    x1 = poly[:, 0].max() + margin
    y0 = poly[:, 1].min() - margin
    y1 = poly[:, 1].max() + margin
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
    a_has = np.zeros(na, dtype=np.bool_)
    b_has = np.zeros(nb, dtype=np.bool_)
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


def near_exit(
    seg: FloatArray,
    sightings: IntArray,
    last_seen: IntArray,
    min_sightings: int,
    recent_scans: int,
    scan: int,
    x: float,
    y: float,
    distance: float,
) -> bool:
    """Whether (x, y) is within ``distance`` of a crossable exit seen in the last ``recent_scans``."""
    for r in range(seg.shape[0]):
        if sightings[r] < min_sightings or scan - last_seen[r] > recent_scans:
            continue
        if point_segment_distance(x, y, seg[r]) <= distance:
            return True
    return False


def update_sides(
    seg: FloatArray,
    side: IntArray,
    side_at: FloatArray,
    mute: IntArray,
    sightings: IntArray,
    last_seen: IntArray,
    x: float,
    y: float,
    band: float,
    min_sightings: int,
    recent_scans: int,
    scan: int,
) -> tuple[IntArray, FloatArray, FloatArray]:
    """The crossing test's per-scan pass over the tracked exits (updates ``side``/``side_at`` in place).

    The robot at (x, y) is on a side of exit r only when farther than
    ``band`` from its line; ``side[r]`` (+1 left of the segment, -1 right,
    0 unknown) and ``side_at[r]`` (where the robot last was clearly on it)
    are updated. A muted exit (``mute[r]`` = the side the robot is heading
    for; a twin of an exit just crossed) reports nothing until the robot is
    clearly on that side, or farther than 2 m from its line. Returns the rows
    whose side changed and that can be crossed (seen ``min_sightings`` times,
    the last within ``recent_scans``), the robot's distance from each one's
    line, and where the robot was on the old side (rows ``(k, 2)``).
    """
    n = seg.shape[0]
    rows = np.empty(n, dtype=np.int64)
    dist = np.empty(n)
    before = np.empty((n, 2))
    k = 0
    for r in range(n):
        ex = seg[r, 2] - seg[r, 0]
        ey = seg[r, 3] - seg[r, 1]
        w = np.hypot(ex, ey)
        if w <= 0.0:
            continue
        d = (ex * (y - seg[r, 1]) - ey * (x - seg[r, 0])) / w
        if abs(d) <= band:
            continue
        s = 1 if d > 0.0 else -1
        if mute[r] != 0:
            if s == mute[r] or abs(d) > 2.0:
                mute[r] = 0
        elif side[r] != 0 and s != side[r] and sightings[r] >= min_sightings and scan - last_seen[r] <= recent_scans:
            rows[k] = r
            dist[k] = abs(d)
            before[k, 0] = side_at[r, 0]
            before[k, 1] = side_at[r, 1]
            k += 1
        side[r] = s
        side_at[r, 0] = x
        side_at[r, 1] = y
    return rows[:k], dist[:k], before[:k]


def _colocated(a: FloatArray, b: FloatArray, max_gap: float) -> bool:
    """Whether the shorter of two surfaces has its midpoint within ``max_gap`` of the longer one.

    Stricter than their ends being near: a short piece must lie *along* the
    longer surface, not just touch one of its ends.
    """
    la = np.hypot(a[2] - a[0], a[3] - a[1])
    lb = np.hypot(b[2] - b[0], b[3] - b[1])
    if la <= lb:
        return point_segment_distance(0.5 * (a[0] + a[2]), 0.5 * (a[1] + a[3]), b) <= max_gap
    return point_segment_distance(0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3]), a) <= max_gap


def _count_matches(
    current: FloatArray,
    dir_j: FloatArray,
    current_side: IntArray,
    remembered: FloatArray,
    dir_k: FloatArray,
    theta: float,
    tx: float,
    ty: float,
    max_angle: float,
    max_gap: float,
    partner: IntArray,
) -> tuple[int, bool, bool]:
    """Matches of the remembered surfaces moved by (theta, tx, ty) onto current ones, one-to-one.

    ``partner[k]`` is set to the current surface remembered surface k matched (-1: none). Returns the
    count and whether matched current surfaces lie left and right of the robot.
    """
    nj = current.shape[0]
    nk = remembered.shape[0]
    c = math.cos(theta)
    s = math.sin(theta)
    seg = np.empty(4)
    used = np.zeros(nj, dtype=np.bool_)
    count = 0
    left = False
    right = False
    for kk in range(nk):
        partner[kk] = -1
        d = dir_k[kk] + theta
        seg[0] = tx + c * remembered[kk, 0] - s * remembered[kk, 1]
        seg[1] = ty + s * remembered[kk, 0] + c * remembered[kk, 1]
        seg[2] = tx + c * remembered[kk, 2] - s * remembered[kk, 3]
        seg[3] = ty + s * remembered[kk, 2] + c * remembered[kk, 3]
        for jj in range(nj):
            if used[jj] or abs(wrap_angle(dir_j[jj] - d)) >= max_angle:
                continue
            if _colocated(current[jj], seg, max_gap):
                used[jj] = True
                partner[kk] = jj
                count += 1
                if current_side[jj] < 0:
                    left = True
                elif current_side[jj] > 0:
                    right = True
                break
    return count, left, right


def _refine(
    current: FloatArray,
    dir_j: FloatArray,
    remembered: FloatArray,
    dir_k: FloatArray,
    theta: float,
    tx: float,
    ty: float,
    partner: IntArray,
) -> tuple[float, float, float]:
    """The motion re-estimated from matched pairs: rotation from their directions, translation by least squares.

    Rotation: the length-weighted mean of the direction differences. Translation: the remembered
    endpoints' distances to the matched current lines squared and summed (a 2 x 2 system); a small
    weight on the midpoints' offsets fixes the direction the lines leave free (all parallel).
    """
    nk = remembered.shape[0]
    sw = 0.0
    sa = 0.0
    for kk in range(nk):
        jj = partner[kk]
        if jj < 0:
            continue
        w = np.hypot(remembered[kk, 2] - remembered[kk, 0], remembered[kk, 3] - remembered[kk, 1])
        sa += w * wrap_angle(dir_j[jj] - (dir_k[kk] + theta))
        sw += w
    if sw <= 0.0:
        return theta, tx, ty
    theta = wrap_angle(theta + sa / sw)
    c = math.cos(theta)
    s = math.sin(theta)
    a11 = 0.0
    a12 = 0.0
    a22 = 0.0
    b1 = 0.0
    b2 = 0.0
    for kk in range(nk):
        jj = partner[kk]
        if jj < 0:
            continue
        nx = -math.sin(dir_j[jj])
        ny = math.cos(dir_j[jj])
        offset = nx * current[jj, 0] + ny * current[jj, 1]
        for e in range(3):
            if e < 2:
                px = remembered[kk, 2 * e]
                py = remembered[kk, 2 * e + 1]
                wx = 1.0
            else:
                px = 0.5 * (remembered[kk, 0] + remembered[kk, 2])
                py = 0.5 * (remembered[kk, 1] + remembered[kk, 3])
                wx = 0.0
            qx = c * px - s * py
            qy = s * px + c * py
            if wx > 0.0:
                r = offset - (nx * qx + ny * qy)
                a11 += nx * nx
                a12 += nx * ny
                a22 += ny * ny
                b1 += nx * r
                b2 += ny * r
            else:  # weak pull of the midpoints together, along and across
                mx = 0.5 * (current[jj, 0] + current[jj, 2]) - qx
                my = 0.5 * (current[jj, 1] + current[jj, 3]) - qy
                a11 += 1e-3
                a22 += 1e-3
                b1 += 1e-3 * mx
                b2 += 1e-3 * my
    det = a11 * a22 - a12 * a12
    if det <= 1e-12:
        return theta, tx, ty
    return theta, (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det


def _seen_empty(x: float, y: float, polys: FloatArray, starts: IntArray, margin: float) -> bool:
    """Whether (x, y) lies inside one of the view polygons (even-odd) by more than ``margin``.

    Polygon ``p`` is ``polys[starts[p]:starts[p + 1]]`` (implicitly closed).
    """
    for p in range(starts.shape[0] - 1):
        lo = starts[p]
        v = starts[p + 1] - lo
        inside = False
        for e in range(v):
            ax = polys[lo + e, 0]
            ay = polys[lo + e, 1]
            bx = polys[lo + (e + 1) % v, 0]
            by = polys[lo + (e + 1) % v, 1]
            if (ay > y) != (by > y):
                if x < ax + (y - ay) * (bx - ax) / (by - ay):
                    inside = not inside
        if not inside:
            continue
        clear = True
        for e in range(v):
            ax = polys[lo + e, 0]
            ay = polys[lo + e, 1]
            bx = polys[lo + (e + 1) % v, 0]
            by = polys[lo + (e + 1) % v, 1]
            t = closest_parameter(x, y, ax, ay, bx, by)
            if np.hypot(ax + t * (bx - ax) - x, ay + t * (by - ay) - y) <= margin:
                clear = False
                break
        if clear:
            return True
    return False


def _conflicts(
    remembered: FloatArray,
    theta: float,
    tx: float,
    ty: float,
    partner: IntArray,
    polys: FloatArray,
    starts: IntArray,
    margin: float,
) -> int:
    """Unmatched remembered surfaces the hypothesis puts where the current place's views saw empty space."""
    c = math.cos(theta)
    s = math.sin(theta)
    n = 0
    for kk in range(remembered.shape[0]):
        if partner[kk] >= 0:
            continue
        mx = 0.5 * (remembered[kk, 0] + remembered[kk, 2])
        my = 0.5 * (remembered[kk, 1] + remembered[kk, 3])
        if _seen_empty(tx + c * mx - s * my, ty + s * mx + c * my, polys, starts, margin):
            n += 1
    return n


def _shift(tx: float, ty: float, theta: float, prior: FloatArray, centre: FloatArray) -> float:
    """How far the motion (theta, tx, ty) puts the place's ``centre`` from where ``prior`` puts it."""
    ch = math.cos(theta)
    sh = math.sin(theta)
    cp = math.cos(prior[2])
    sp = math.sin(prior[2])
    return float(
        np.hypot(
            tx + ch * centre[0] - sh * centre[1] - (prior[0] + cp * centre[0] - sp * centre[1]),
            ty + sh * centre[0] + ch * centre[1] - (prior[1] + sp * centre[0] + cp * centre[1]),
        )
    )


def match_structure(
    current: FloatArray,
    current_side: IntArray,
    remembered: FloatArray,
    max_angle: float,
    max_gap: float,
    min_matches: int,
    anchors: int,
    polygons: FloatArray,
    polygon_starts: IntArray,
    max_conflicts: int,
    prior: FloatArray,
    centre: FloatArray,
    max_turn: float,
    max_shift: float,
) -> tuple[bool, int, float, float, float]:
    """Algorithm 6: does a hypothesis ``S_j = S_k`` bring more than 4 remembered surfaces onto current ones?

    ``current`` ``(J, 4)`` are the current place's surfaces (map frame),
    ``current_side`` ``(J,)`` the side of the robot each lies on (-1 left,
    +1 right, 0 neither), ``remembered`` ``(K, 4)`` the remembered place's
    surfaces in its own frame. For every pair (j, k) in order, and for each
    of ``anchors`` anchorings (1: midpoint on midpoint; 3: also left end on
    left end and right end on right end), the rigid motion turning S_k's
    direction onto S_j's and putting the anchor of S_k on that of S_j is
    applied to every remembered surface; a transformed surface matches when
    a current surface not yet matched (pairs are one-to-one, so pieces of
    one wall cannot all count against one long surface) differs in
    direction by less than ``max_angle`` and the shorter of the two lies
    along the longer, its midpoint within ``max_gap`` of it (:func:`_colocated`).
    A hypothesis with at least two matches is refined once from its matched
    pairs (:func:`_refine`: one surface fixes a direction badly, so a small
    angle error would push far surfaces out of the 40 cm) and counted again.
    The first hypothesis with at least ``min_matches`` matches whose matched
    current surfaces lie on both sides of the robot, and that puts at most
    ``max_conflicts`` unmatched remembered surfaces where the current place's
    views saw empty space (inside one of ``polygons`` by more than
    ``max_gap``: the view polygons of Algorithm 3, which would have deleted
    them; polygon p is ``polygons[polygon_starts[p]:polygon_starts[p + 1]]``),
    confirms (line 11's break). ``prior`` ``(x, y, theta)`` is where the
    perceptual map put the remembered place's frame: only hypotheses turning
    it by at most ``max_turn`` are tried, and one that moves the place's
    ``centre`` (own frame) farther than ``max_shift`` from where the prior
    puts it does not confirm. Returns ``(confirmed, best count, theta, tx, ty)``: the motion of
    the confirming hypothesis (or of the best one) mapping the remembered
    frame into the map frame.
    """
    nj = current.shape[0]
    nk = remembered.shape[0]
    dir_j = np.empty(nj)
    for j in range(nj):
        dir_j[j] = math.atan2(current[j, 3] - current[j, 1], current[j, 2] - current[j, 0])
    dir_k = np.empty(nk)
    for k in range(nk):
        dir_k[k] = math.atan2(remembered[k, 3] - remembered[k, 1], remembered[k, 2] - remembered[k, 0])
    partner = np.empty(nk, dtype=np.int64)
    best = -1
    best_theta = 0.0
    best_tx = 0.0
    best_ty = 0.0
    for j in range(nj):
        for k in range(nk):
            theta0 = wrap_angle(dir_j[j] - dir_k[k])
            if abs(wrap_angle(theta0 - prior[2])) > max_turn:
                continue
            c = math.cos(theta0)
            s = math.sin(theta0)
            for a in range(anchors):
                theta = theta0
                if a == 0:
                    jx = 0.5 * (current[j, 0] + current[j, 2])
                    jy = 0.5 * (current[j, 1] + current[j, 3])
                    kx = 0.5 * (remembered[k, 0] + remembered[k, 2])
                    ky = 0.5 * (remembered[k, 1] + remembered[k, 3])
                else:
                    e = 2 * (a - 1)
                    jx = current[j, e]
                    jy = current[j, e + 1]
                    kx = remembered[k, e]
                    ky = remembered[k, e + 1]
                tx = jx - (c * kx - s * ky)
                ty = jy - (s * kx + c * ky)
                # a hypothesis that moves the place's centre far beyond max_shift is not counted at all
                # (its refinement could not bring it back: one metre of slack)
                if _shift(tx, ty, theta, prior, centre) > max_shift + 1.0:
                    continue
                count, left, right = _count_matches(
                    current, dir_j, current_side, remembered, dir_k, theta, tx, ty, max_angle, max_gap, partner
                )
                if 2 <= count and not (count >= min_matches and left and right):
                    rt, rx, ry = _refine(current, dir_j, remembered, dir_k, theta, tx, ty, partner)
                    count2, left2, right2 = _count_matches(
                        current, dir_j, current_side, remembered, dir_k, rt, rx, ry, max_angle, max_gap, partner
                    )
                    if count2 > count:
                        count, left, right, theta, tx, ty = count2, left2, right2, rt, rx, ry
                if count > best:
                    best = count
                    best_theta = theta
                    best_tx = tx
                    best_ty = ty
                if count >= min_matches and left and right:
                    shift = _shift(tx, ty, theta, prior, centre)
                    if shift <= max_shift and abs(wrap_angle(theta - prior[2])) <= max_turn:
                        conflicts = _conflicts(remembered, theta, tx, ty, partner, polygons, polygon_starts, max_gap)
                        if conflicts <= max_conflicts:
                            return True, count, theta, tx, ty
    return False, max(best, 0), best_theta, best_tx, best_ty
