"""Fewer kernel calls per scan: kernels that are always called one after the other, as one compiled entry point.

Issue 24 asks for Albot1+ at most a third of KISS-ICP's per-scan cost. Once
the kernels' own arithmetic is compiled, much of what is left of a scan is
the price of crossing between Python and compiled code: numba's dispatcher
types every argument of every call, and every array a kernel returns is
boxed (a Python call into numba's unpickling memo each). Two pairs of
calls made on (nearly) every scan are fused here, each into one kernel
that calls the same kernels as before, on the same values, in the same
order, so every bit is as it was:

* :func:`perceive`: the view (:func:`~albot1.methods.albot1.perception.kernels.build_view`, on the beams
  reversed into the thesis's left-to-right order, as
  :func:`~albot1.methods.albot1.perception.view.construct_view` does), its landmarks
  (:func:`~albot1.methods.albot1.perception.kernels.landmark_rows`) and, for Albot1+, the scan's points
  (:func:`~albot1.methods.albot1.mapping.pose_kernels.scan_points`): three calls and three numpy
  copies become one call.
* :func:`refine_and_score`: Albot1+'s pose fit
  (:func:`~albot1.methods.albot1.mapping.pose_kernels.refine_pose`) and the ambiguity test's costs at the
  fitted pose and at the odometry's prediction
  (:func:`~albot1.methods.albot1.mapping.ambiguity.measurement_costs`), which ``plus`` evaluates right
  after every fit: two calls, a numpy array of the two poses and three boxed arrays fewer.

The kernels called inside stay kernels of their own (the readable pieces,
their tests and their other callers); numba compiles them into these. As
with ``update_surfaces`` calling ``resolve_partial``, the Python source of a
fused kernel (``accelerate = false``) still calls the compiled pieces, so
for everything in Python use ``NUMBA_DISABLE_JIT=1``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import kernel, readonly_float64
from albot1.methods.albot1.mapping.ambiguity import measurement_costs
from albot1.methods.albot1.mapping.pose_kernels import refine_pose, scan_points
from albot1.methods.albot1.perception.kernels import build_view, landmark_rows
from albot1.methods.albot1.perception.landmarks import Landmarks
from albot1.methods.albot1.perception.view import View, ViewParams, seam_at_gap

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@kernel
def perceive(
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
    landmark_min_length: float,
    points_range: float,
    points_stride: int,
) -> tuple[FloatArray, IntArray, IntArray, IntArray, IntArray, FloatArray, IntArray, FloatArray]:
    """One scan's view, landmarks and (``points_stride`` > 0) points, from REP-103 beams (angles ascending).

    Returns ``build_view``'s four arrays, ``landmark_rows``' three, and
    ``scan_points(ranges, angles, points_range, points_stride)`` (``(0, 2)``
    when ``points_stride`` is 0: the thesis presets use no points).
    """
    n = ranges.shape[0]
    # The thesis's left-to-right order, as construct_view's reversed copies (values copied, not computed).
    r = np.empty(n)
    a = np.empty(n)
    for i in range(n):
        r[i] = ranges[n - 1 - i]
        a[i] = angles[n - 1 - i]
    surfaces, kinds, beams, cluster = build_view(
        r,
        a,
        max_range,
        cluster_gap,
        cluster_size,
        break_point_height,
        surface_length,
        corner_min_turn,
        occlusion_margin,
        continuation_tolerance,
        end_spacing_max,
        grazing,
        fit_lines,
    )
    rows, lm_surfaces, lm_kinds = landmark_rows(surfaces, kinds, landmark_min_length)
    points = scan_points(ranges, angles, points_range, points_stride) if points_stride > 0 else np.empty((0, 2))
    return surfaces, kinds, beams, cluster, rows, lm_surfaces, lm_kinds, points


#: The signature of :func:`perceive` (for :func:`perceive_scan`'s ``kernel``).
Perceive = Callable[..., tuple[FloatArray, IntArray, IntArray, IntArray, IntArray, FloatArray, IntArray, FloatArray]]


@kernel
def refine_and_score(
    starts: FloatArray,
    lm_view: FloatArray,
    lm_map: FloatArray,
    point_ok: BoolArray,
    points: FloatArray,
    ref: FloatArray,
    prior_x: float,
    prior_y: float,
    prior_phi: float,
    line_sigma: float,
    point_sigma: float,
    scan_sigma: float,
    huber: float,
    gate: float,
    iterations: int,
    overhang: float,
) -> tuple[float, float, float, FloatArray, float, float, float, int, int]:
    """``refine_pose`` without a prior (its information 0), then ``measurement_costs`` at the fit and the prior.

    ``(prior_x, prior_y, prior_phi)`` is the odometry's prediction: the
    point the fit is measured against (no information: the fit is the
    view's alone) and the second pose the ambiguity test scores. Returns the
    fitted pose and its information (as ``refine_pose``), then the cost at
    the fit, the cost at the prediction, the fit's matched cost, its terms
    and its independent terms (as ``measurement_costs``).
    """
    x, y, phi, info = refine_pose(
        starts,
        lm_view,
        lm_map,
        point_ok,
        points,
        ref,
        prior_x,
        prior_y,
        prior_phi,
        0.0,
        0.0,
        line_sigma,
        point_sigma,
        scan_sigma,
        huber,
        gate,
        iterations,
        overhang,
    )
    poses = np.empty((2, 3))
    poses[0, 0] = x
    poses[0, 1] = y
    poses[0, 2] = phi
    poses[1, 0] = prior_x
    poses[1, 1] = prior_y
    poses[1, 2] = prior_phi
    costs, _, matched, terms, independent = measurement_costs(
        poses, lm_view, lm_map, point_ok, points, ref, line_sigma, point_sigma, scan_sigma, huber, gate, overhang
    )
    return x, y, phi, info, costs[0], costs[1], matched, terms, independent


def perceive_scan(
    ranges: FloatArray,
    angles: FloatArray,
    params: ViewParams,
    landmark_min_length: float,
    points_range: float,
    points_stride: int,
    kernel: Perceive = perceive,
) -> tuple[View, Landmarks, FloatArray]:
    """``construct_view``, ``find_landmarks`` and Albot1+'s ``scan_points`` of one REP-103 scan in one call.

    ``points_stride`` 0: no points (``(0, 2)``). The beams are passed as
    :func:`~albot1.methods.albot1.compiled.readonly_float64` arrays, as
    Albot1+'s points were, so the kernel has one signature. ``kernel``:
    :func:`perceive`, compiled or as written. A 360-degree scan starts at its
    widest gap, as in ``construct_view`` (:func:`.view.seam_at_gap`).
    """
    ranges, angles = seam_at_gap(
        np.asarray(ranges, dtype=np.float64), np.asarray(angles, dtype=np.float64), params.max_range
    )
    surfaces, kinds, beams, cluster, rows, lm_surfaces, lm_kinds, points = kernel(
        readonly_float64(ranges),
        readonly_float64(angles),
        params.max_range,
        params.cluster_gap,
        params.cluster_size,
        params.break_point_height,
        params.surface_length,
        params.corner_min_turn,
        params.occlusion_margin,
        params.continuation_tolerance,
        params.end_spacing_max,
        params.end_spacing_grazing,
        params.fit_lines,
        landmark_min_length,
        points_range,
        points_stride,
    )
    return View(surfaces, kinds, beams, cluster), Landmarks(rows, lm_surfaces, lm_kinds), points
