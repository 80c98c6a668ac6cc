"""The places layer's structural matcher kernel: the best rigid motion of remembered onto current surfaces.

A numba kernel (:mod:`albot1.methods.albot1.compiled`) and the loops it
calls, in the thesis frame.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import wrap_angle
from albot1.geometry.segments import closest_parameter, point_segment_distance
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import falses, jitable, kernel

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@jitable
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


@jitable
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
    used = falses(nj)
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


@jitable
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


@jitable
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


@jitable
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


@jitable
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


@kernel
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
