"""The per-scan loop of Albot1+'s pose: robust Gauss-Newton over landmark and scan terms.

Plain Python over numpy arrays and scalars in the subset numba compiles;
numba compiles them (:mod:`albot1.methods.albot1.compiled`) and
:class:`albot1.methods.albot1.mapping.kernels.MappingKernels` hands out the
compiled or the Python version of the same source (tests run both on the
same inputs). The maths is in ``docs/albot1-mapper.md`` ("Albot1+"); the caller
is :mod:`albot1.methods.albot1.mapping.plus`.

The unknown is the view's pose ``(x, y, phi)`` in the map (thesis frame): a
view point ``v`` lands at ``R(phi) v + (x, y)``. Residuals, each weighted by
``1 / sigma^2`` and a Huber weight (threshold ``huber`` sigmas, by
iteratively reweighted least squares):

* every endpoint of every recognised landmark, point-to-line against the
  landmark's map copy (``line_sigma``);
* every endpoint stable in both views, point-to-point against its map copy
  (``point_sigma``): the only terms that fix the position *along* a wall;
* every view point (``points``), point-to-line against the nearest surface
  of the last update view (``ref``, already in the map) within ``gate``
  metres (``scan_sigma``), re-associated at every iteration;
* an optional prior ``(prior_x, prior_y, prior_phi)`` with information
  ``prior_info_xy`` (1/m^2, both axes) and ``prior_info_phi`` (1/rad^2).

Distances use ``np.hypot`` (see :mod:`albot1.methods.albot1.mapping.kernels`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import wrap_angle
from albot1.geometry.segments import clip_parameter
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import jitable, kernel
from albot1.methods.albot1.mapping.overlap import overhangs_along

BoolArray = NDArray[np.bool_]

#: Levenberg-Marquardt damping of each Gauss-Newton step (1/m^2, 1/rad^2): negligible against any direction the
#: view fixes (thousands), it stops steps along one it does not.
DAMPING_XY = 1.0
DAMPING_PHI = 4.0
#: The largest Gauss-Newton step (m, rad): nearest-surface associations hold only near the current pose.
MAX_STEP_M = 0.5
MAX_STEP_RAD = 0.1


@jitable
def huber_weight(residual: float, threshold: float) -> float:
    """The IRLS weight of Huber's loss: 1 inside ``threshold``, ``threshold / |r|`` beyond."""
    a = abs(residual)
    if a <= threshold:
        return 1.0
    return threshold / a


@jitable
def huber_cost(residual: float, threshold: float) -> float:
    """Huber's loss: ``r^2 / 2`` inside ``threshold``, linear beyond (the cost :func:`huber_weight` minimises)."""
    a = abs(residual)
    if a <= threshold:
        return 0.5 * a * a
    return threshold * (a - 0.5 * threshold)


#: The sums of the Gauss-Newton normal equations, ``(h00, h01, h02, h11, h12, h22, b0, b1, b2)``: the upper
#: triangle of the 3x3 matrix ``H`` and the right-hand side ``b`` over ``(x, y, phi)``.
NormalSums = tuple[float, float, float, float, float, float, float, float, float]


@jitable
def add_point_to_line(
    sums: NormalSums,
    nx: float,
    ny: float,
    ox: float,
    oy: float,
    dx: float,
    dy: float,
    weight: float,
    threshold: float,
) -> NormalSums:
    """``sums`` with one robust point-to-line term added: landmark and scan terms share this one implementation.

    The point sits at offset ``(ox, oy)`` from a point of the line with unit
    normal ``(nx, ny)``; ``(dx, dy)`` is the rotated view point ``R(phi) v``,
    so the residual's Jacobian is ``(nx, ny, n x (R v))``. ``weight`` is
    ``1 / sigma^2`` and ``threshold`` the Huber threshold in metres. The
    sums go in and come back as scalars, not an array, so that the compiled
    caller (which inlines this) keeps them in registers; each term is added
    in call order with the operations the caller once wrote out inline, so
    poses stay bit-identical to earlier runs.
    """
    h00, h01, h02, h11, h12, h22, b0, b1, b2 = sums
    r = nx * ox + ny * oy
    j2 = ny * dx - nx * dy
    w = weight * huber_weight(r, threshold)
    return (
        h00 + w * nx * nx,
        h01 + w * nx * ny,
        h02 + w * nx * j2,
        h11 + w * ny * ny,
        h12 + w * ny * j2,
        h22 + w * j2 * j2,
        b0 + w * nx * r,
        b1 + w * ny * r,
        b2 + w * j2 * r,
    )


#: A squared distance beyond ``best^2`` times this is certainly not nearer than ``best``: the rounding of the
#: square sums (a few units of 2^-53) and of ``np.hypot`` (under one unit) are far below 2^-30, so skipping
#: ``np.hypot`` there leaves every comparison, and every bit, as it was (issue 24: ``hypot`` is libm's slowest
#: call in the scan terms). Only where ``best^2`` is far from underflow (``best`` above :data:`SQUARE_SAFE`).
CERTAINLY_FARTHER = 1.0 + 2.0**-30
SQUARE_SAFE = 2.0**-500


@jitable
def surface_boxes(ref: FloatArray, margin: float) -> FloatArray:
    """Each surface's bounding box grown by ``margin`` and what every point's test of it repeats: ``(m, 8)``.

    Columns: xmin, ymin, xmax, ymax, then ``ex, ey`` (``b - a``), ``l2 = ex^2 + ey^2`` and ``sqrt(l2)``,
    computed once per surface instead of once per point and surface (:func:`nearest_surface`).
    """
    boxes = np.empty((ref.shape[0], 8))
    for j in range(ref.shape[0]):
        boxes[j, 0] = min(ref[j, 0], ref[j, 2]) - margin
        boxes[j, 1] = min(ref[j, 1], ref[j, 3]) - margin
        boxes[j, 2] = max(ref[j, 0], ref[j, 2]) + margin
        boxes[j, 3] = max(ref[j, 1], ref[j, 3]) + margin
        ex = ref[j, 2] - ref[j, 0]
        ey = ref[j, 3] - ref[j, 1]
        l2 = ex * ex + ey * ey
        boxes[j, 4] = ex
        boxes[j, 5] = ey
        boxes[j, 6] = l2
        boxes[j, 7] = math.sqrt(l2)
    return boxes


@jitable
def nearest_surface(
    x: float, y: float, ref: FloatArray, boxes: FloatArray, gate: float, overhang: float
) -> tuple[int, float]:
    """The surface of ``ref`` nearest the point and its distance, if nearer than ``gate``; else ``(-1, gate)``.

    ``boxes`` (:func:`surface_boxes` grown by ``gate``) skip the surfaces
    that cannot be within ``gate`` before any distance is computed; a surface
    the point's projection overhangs by more than ``overhang`` m is skipped
    too (:mod:`albot1.methods.albot1.mapping.overlap`; ``NO_LIMIT``: none is).
    The distance is :func:`~albot1.geometry.segments.point_segment_distance`'s arithmetic, with the
    projection computed once for the overlap test and the clipping, and ``np.hypot`` only where the
    squared distance leaves the comparison open (:data:`CERTAINLY_FARTHER`).
    """
    best = gate
    found = -1
    for j in range(ref.shape[0]):
        if x < boxes[j, 0] or x > boxes[j, 2] or y < boxes[j, 1] or y > boxes[j, 3]:
            continue
        ex = boxes[j, 4]
        ey = boxes[j, 5]
        l2 = boxes[j, 6]
        t = 0.0
        if l2 > 0.0:
            along = (x - ref[j, 0]) * ex + (y - ref[j, 1]) * ey
            if overhangs_along(along, l2, boxes[j, 7], overhang):
                continue
            t = clip_parameter(along, l2)
        dx = ref[j, 0] + t * ex - x
        dy = ref[j, 1] + t * ey - y
        if best > SQUARE_SAFE and dx * dx + dy * dy > best * best * CERTAINLY_FARTHER:
            continue
        d = np.hypot(dx, dy)
        if d < best:
            best = d
            found = j
    return found, best


@jitable
def pose_cost(
    x: float,
    y: float,
    phi: float,
    lm_view: FloatArray,
    lm_map: FloatArray,
    point_ok: BoolArray,
    points: FloatArray,
    ref: FloatArray,
    boxes: FloatArray,
    line_sigma: float,
    point_sigma: float,
    scan_sigma: float,
    huber: float,
    gate: float,
    overhang: float,
    bound: float,
) -> float:
    """The robust cost of the measurement terms at pose ``(x, y, phi)`` (residuals in sigmas).

    A view point with no reference surface within ``gate`` costs as much as
    one exactly at the gate, so poses that explain fewer points do not look
    cheaper. The sum stops once it reaches ``bound`` and returns what it has
    (at least ``bound``): every term is at least 0 (Huber's loss with a
    positive threshold, the config's ``gt=0``) and adding a non-negative
    float never lowers a sum, so the full cost could only be higher. The
    choice of the cheapest start (:func:`refine_pose`) passes the lowest
    cost so far and skips most points of a start that cannot win, with the
    same choice as the full sums (issue 24); ``np.inf``: the full cost.
    """
    c = math.cos(phi)
    s = math.sin(phi)
    total = 0.0
    for i in range(lm_view.shape[0]):
        ex = lm_map[i, 2] - lm_map[i, 0]
        ey = lm_map[i, 3] - lm_map[i, 1]
        length = np.hypot(ex, ey)
        for e in range(2):
            tx = x + c * lm_view[i, 2 * e] - s * lm_view[i, 2 * e + 1]
            ty = y + s * lm_view[i, 2 * e] + c * lm_view[i, 2 * e + 1]
            if length > 0.0:
                r = (-ey * (tx - lm_map[i, 0]) + ex * (ty - lm_map[i, 1])) / length
                total += huber_cost(r / line_sigma, huber)
            if point_ok[i, e]:
                total += huber_cost(np.hypot(tx - lm_map[i, 2 * e], ty - lm_map[i, 2 * e + 1]) / point_sigma, huber)
    for p in range(points.shape[0]):
        if total >= bound:
            return total
        tx = x + c * points[p, 0] - s * points[p, 1]
        ty = y + s * points[p, 0] + c * points[p, 1]
        best = nearest_surface(tx, ty, ref, boxes, gate, overhang)[1]
        total += huber_cost(best / scan_sigma, huber)
    return total


@jitable
def repeats_earlier(starts: FloatArray, q: int) -> bool:
    """Whether start ``q`` equals an earlier one (the thesis pose is also its landmark's candidate pose)."""
    for r in range(q):
        if starts[r, 0] == starts[q, 0] and starts[r, 1] == starts[q, 1] and starts[r, 2] == starts[q, 2]:
            return True
    return False


@kernel
def refine_pose(
    starts: FloatArray,
    lm_view: FloatArray,
    lm_map: FloatArray,
    point_ok: BoolArray,
    points: FloatArray,
    ref: FloatArray,
    prior_x: float,
    prior_y: float,
    prior_phi: float,
    prior_info_xy: float,
    prior_info_phi: float,
    line_sigma: float,
    point_sigma: float,
    scan_sigma: float,
    huber: float,
    gate: float,
    iterations: int,
    overhang: float,
) -> tuple[float, float, float, FloatArray]:
    """The pose minimising the weighted robust residuals, from the cheapest of ``starts`` ``(c, 3)``.

    ``lm_view`` / ``lm_map`` ``(k, 4)``: the recognised landmarks in the view
    and their map copies; ``point_ok`` ``(k, 2)``: which endpoints are stable
    in both. ``points`` ``(n, 2)``: view points; ``ref`` ``(m, 4)``: the last
    update view's surfaces in the map. Returns the pose and the 3x3
    information matrix of the measurement terms alone (no prior) at the
    last linearisation, which says how well the view fixes each direction.
    ``overhang``: how far beyond a surface's end a view point may still be
    matched to it (:mod:`albot1.methods.albot1.mapping.overlap`; ``NO_LIMIT``:
    anywhere within ``gate``, as before the rule existed).
    Stops after ``iterations`` Gauss-Newton steps or when a step moves less
    than 1 micrometre and 0.1 microradian.
    """
    boxes = surface_boxes(ref, gate)
    # The start with the lowest robust cost (a mismatched landmark places the robot far off).
    chosen = 0
    lowest = np.inf
    for q in range(starts.shape[0]):
        if repeats_earlier(starts, q):
            continue  # an earlier start is the same pose: same cost, and a tie keeps the earlier one anyway
        cost = pose_cost(
            starts[q, 0],
            starts[q, 1],
            starts[q, 2],
            lm_view,
            lm_map,
            point_ok,
            points,
            ref,
            boxes,
            line_sigma,
            point_sigma,
            scan_sigma,
            huber,
            gate,
            overhang,
            lowest,
        )
        if cost < lowest:
            lowest = cost
            chosen = q
    x = starts[chosen, 0]
    y = starts[chosen, 1]
    phi = starts[chosen, 2]
    k = lm_view.shape[0]
    n = points.shape[0]
    m = ref.shape[0]
    w_line = 1.0 / (line_sigma * line_sigma)
    w_point = 1.0 / (point_sigma * point_sigma)
    w_scan = 1.0 / (scan_sigma * scan_sigma)
    # Unit normals of the landmarks' map copies and of the reference surfaces (0 for a degenerate one).
    # (np.empty and a 0.0 where nothing is written, not np.zeros: one numpy routine less to compile)
    lnx = np.empty(k)
    lny = np.empty(k)
    for i in range(k):
        ex = lm_map[i, 2] - lm_map[i, 0]
        ey = lm_map[i, 3] - lm_map[i, 1]
        length = np.hypot(ex, ey)
        if length > 0.0:
            lnx[i] = -ey / length
            lny[i] = ex / length
        else:
            lnx[i] = 0.0
            lny[i] = 0.0
    rnx = np.empty(m)
    rny = np.empty(m)
    for j in range(m):
        ex = ref[j, 2] - ref[j, 0]
        ey = ref[j, 3] - ref[j, 1]
        length = np.hypot(ex, ey)
        if length > 0.0:
            rnx[j] = -ey / length
            rny[j] = ex / length
        else:
            rnx[j] = 0.0
            rny[j] = 0.0
    info = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            info[i, j] = 0.0
    for _ in range(iterations):
        c = math.cos(phi)
        s = math.sin(phi)
        h00 = 0.0
        h01 = 0.0
        h02 = 0.0
        h11 = 0.0
        h12 = 0.0
        h22 = 0.0
        b0 = 0.0
        b1 = 0.0
        b2 = 0.0
        for i in range(k):
            for e in range(2):
                vx = lm_view[i, 2 * e]
                vy = lm_view[i, 2 * e + 1]
                dx = c * vx - s * vy
                dy = s * vx + c * vy
                tx = x + dx
                ty = y + dy
                # Point-to-line against the landmark's map copy.
                h00, h01, h02, h11, h12, h22, b0, b1, b2 = add_point_to_line(
                    (h00, h01, h02, h11, h12, h22, b0, b1, b2),
                    lnx[i],
                    lny[i],
                    tx - lm_map[i, 0],
                    ty - lm_map[i, 1],
                    dx,
                    dy,
                    w_line,
                    huber * line_sigma,
                )
                if point_ok[i, e]:
                    # Point-to-point: rows (1, 0, -dy) and (0, 1, dx), one Huber weight on the distance.
                    rx = tx - lm_map[i, 2 * e]
                    ry = ty - lm_map[i, 2 * e + 1]
                    w = w_point * huber_weight(np.hypot(rx, ry), huber * point_sigma)
                    h00 += w
                    h02 -= w * dy
                    h11 += w
                    h12 += w * dx
                    h22 += w * (dx * dx + dy * dy)
                    b0 += w * rx
                    b1 += w * ry
                    b2 += w * (dx * ry - dy * rx)
        for p in range(n):
            vx = points[p, 0]
            vy = points[p, 1]
            dx = c * vx - s * vy
            dy = s * vx + c * vy
            tx = x + dx
            ty = y + dy
            found = nearest_surface(tx, ty, ref, boxes, gate, overhang)[0]
            if found < 0:
                continue
            # Point-to-line against the nearest reference surface.
            h00, h01, h02, h11, h12, h22, b0, b1, b2 = add_point_to_line(
                (h00, h01, h02, h11, h12, h22, b0, b1, b2),
                rnx[found],
                rny[found],
                tx - ref[found, 0],
                ty - ref[found, 1],
                dx,
                dy,
                w_scan,
                huber * scan_sigma,
            )
        info[0, 0] = h00
        info[0, 1] = h01
        info[0, 2] = h02
        info[1, 0] = h01
        info[1, 1] = h11
        info[1, 2] = h12
        info[2, 0] = h02
        info[2, 1] = h12
        info[2, 2] = h22
        if prior_info_xy > 0.0:
            h00 += prior_info_xy
            h11 += prior_info_xy
            b0 += prior_info_xy * (x - prior_x)
            b1 += prior_info_xy * (y - prior_y)
        if prior_info_phi > 0.0:
            h22 += prior_info_phi
            b2 += prior_info_phi * wrap_angle(phi - prior_phi)
        # Solve (H + D) d = -b (symmetric 3x3, by cofactors). The damping D (Levenberg-Marquardt) keeps a direction
        # nothing fixes, along a featureless corridor, from taking a step on rounding noise; it does not move the
        # solution where the gradient vanishes.
        a00 = h00 + DAMPING_XY
        a11 = h11 + DAMPING_XY
        a22 = h22 + DAMPING_PHI
        c00 = a11 * a22 - h12 * h12
        c01 = h02 * h12 - h01 * a22
        c02 = h01 * h12 - h02 * a11
        det = a00 * c00 + h01 * c01 + h02 * c02
        if not det > 0.0:
            break
        c11 = a00 * a22 - h02 * h02
        c12 = h01 * h02 - a00 * h12
        c22 = a00 * a11 - h01 * h01
        d0 = -(c00 * b0 + c01 * b1 + c02 * b2) / det
        d1 = -(c01 * b0 + c11 * b1 + c12 * b2) / det
        d2 = -(c02 * b0 + c12 * b1 + c22 * b2) / det
        # A trust region: one step moves at most MAX_STEP_M and MAX_STEP_RAD (associations are only local).
        shrink = max(1.0, np.hypot(d0, d1) / MAX_STEP_M, abs(d2) / MAX_STEP_RAD)
        d0 /= shrink
        d1 /= shrink
        d2 /= shrink
        x += d0
        y += d1
        phi = wrap_angle(phi + d2)
        if abs(d0) + abs(d1) < 1e-6 and abs(d2) < 1e-7:
            break
    return x, y, phi, info


@kernel
def scan_points(ranges: FloatArray, angles: FloatArray, max_range: float, stride: int) -> FloatArray:
    """Every ``stride``-th return within ``max_range`` (REP-103 beams), as points ``(n, 2)`` in the thesis frame.

    A return counts when its range is a number, positive and at most
    ``max_range`` (3.1.3 step 1); ``stride`` counts returns, not beams.
    """
    count = 0
    for i in range(ranges.shape[0]):
        r = ranges[i]
        if r == r and r > 0.0 and r <= max_range:
            count += 1
    out = np.empty(((count + stride - 1) // stride, 2))
    k = 0
    seen = 0
    for i in range(ranges.shape[0]):
        r = ranges[i]
        if r == r and r > 0.0 and r <= max_range:
            if seen % stride == 0:
                out[k, 0] = -r * math.sin(angles[i])
                out[k, 1] = r * math.cos(angles[i])
                k += 1
            seen += 1
    return out
