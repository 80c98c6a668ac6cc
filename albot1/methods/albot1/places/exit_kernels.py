"""The places layer's exit kernels: exits in a view, exits seen through, and which side of an exit the robot is.

Numba kernels (:mod:`albot1.methods.albot1.compiled`). Geometry is in the
thesis frame (robot at the origin facing +y, surfaces left to right);
endpoint labels are those of :mod:`albot1.methods.albot1.perception.endpoints`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.segments import orientation, point_segment_distance
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import falses, kernel
from albot1.methods.albot1.ordering import stable_order
from albot1.methods.albot1.perception.endpoints import CORNER, OCCLUDING

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@kernel
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
    order = stable_order(cw[:n])
    used_left = falses(m)
    used_right = falses(m)
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


@kernel
def seen_through(
    seg: FloatArray, ids: IntArray, crossable: BoolArray, ox: float, oy: float, points: FloatArray
) -> IntArray:
    """For each point: the id of the first crossable exit segment the line from (ox, oy) to it passes through.

    -1 where it passes through none; with several, the one met first along the line.
    """
    n = points.shape[0]
    out = np.empty(n, dtype=np.int64)
    for i in range(n):  # a loop, not np.full: one numpy routine less to compile
        out[i] = -1
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


@kernel
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


@kernel
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
