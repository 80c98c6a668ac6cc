"""Albot1+'s ambiguity test: does the view itself tell its fitted pose from the odometry's prediction?

A pose fit can disagree with the odometry for two reasons: the odometry is
off (the fit should win), or the view does not decide between the two poses
-- a wrong association, a corridor, surfaces seen at grazing angles -- and
the fit's minimum is one of several near-equal ones (the odometry should
win). The learnt odometry spread (:class:`~albot1.methods.albot1.mapping.plus.OdometryNoise`)
cannot tell these apart: it holds the views' error as well as the odometry's.
The measurement can: evaluate the same robust cost (landmark and scan terms,
:func:`~albot1.methods.albot1.mapping.pose_kernels.pose_cost`) at the fitted
pose and at the odometry's prediction. Under the hypothesis that the
prediction is the true pose, twice the cost difference, in units of the fit's
own residual variance, is a likelihood-ratio statistic with (about) three
degrees of freedom; below its ``ambiguity_probability`` quantile the view
does not refute the odometry and the prediction is kept. Bad odometry
explains the scan badly (far above the quantile), so there the fit is kept.

The residual variance is the fit's own (its mean squared residual in sigmas),
not the stated one, so a view whose points scatter more than ``scan_sigma``
does not refute the odometry on its scatter alone; and the residuals of the
points of one surface are not independent (they share that surface's fit
error), so the statistic counts ``independent`` terms, not every point
(:func:`effective_terms`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import Pose
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import jitable, kernel
from albot1.methods.albot1.mapping.overlap import NO_LIMIT
from albot1.methods.albot1.mapping.pose_kernels import huber_cost, nearest_surface, pose_cost, surface_boxes

#: Independent terms a surface's points count for at most: its offset and its direction are what its fit error moves.
TERMS_PER_SURFACE = 2


@jitable
def effective_terms(landmark_terms: int, per_surface: NDArray[np.int64]) -> tuple[int, int]:
    """``(terms, independent)``: the residual terms of a view, and how many of them are independent.

    Every landmark term counts; the points on one reference surface count for
    at most :data:`TERMS_PER_SURFACE` (a straight surface's fit error is an
    offset and a turn, shared by all its points).
    """
    terms = landmark_terms
    independent = landmark_terms
    for k in range(per_surface.shape[0]):
        terms += per_surface[k]
        independent += min(per_surface[k], TERMS_PER_SURFACE)
    return terms, independent


@kernel
def measurement_costs(
    poses: FloatArray,
    lm_view: FloatArray,
    lm_map: FloatArray,
    point_ok: NDArray[np.bool_],
    points: FloatArray,
    ref: FloatArray,
    line_sigma: float,
    point_sigma: float,
    scan_sigma: float,
    huber: float,
    gate: float,
    overhang: float,
) -> tuple[FloatArray, NDArray[np.int64], float, int, int]:
    """The robust cost of the view's terms at each of ``poses`` ``(c, 3)``, and the fit's terms at the first.

    Costs are :func:`~albot1.methods.albot1.mapping.pose_kernels.pose_cost`'s
    (residuals in sigmas, ``r^2 / 2`` inside the Huber threshold; a point with
    no surface within ``gate`` costs as much as one at the gate; ``overhang``:
    the overlap rule, :mod:`albot1.methods.albot1.mapping.overlap`). At the first
    pose (the fitted one): per reference surface, how many view points are
    associated with it, the cost of the associated terms alone (landmarks and
    matched points: the residuals the fit's variance is estimated from), and
    :func:`effective_terms` of them. The first pose's cost is summed in one pass
    with its associations, in :func:`pose_cost`'s order (landmarks, then the
    points in turn), so it is that function's value to the bit.
    """
    boxes = surface_boxes(ref, gate)
    costs = np.empty(poses.shape[0])
    for q in range(1, poses.shape[0]):
        costs[q] = pose_cost(
            poses[q, 0],
            poses[q, 1],
            poses[q, 2],
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
            np.inf,
        )
    per_surface = np.empty(ref.shape[0], dtype=np.int64)
    for j in range(ref.shape[0]):  # a loop, not np.zeros: one numpy routine less to compile
        per_surface[j] = 0
    matched = 0.0
    landmark_terms = 0
    for i in range(lm_map.shape[0]):
        if np.hypot(lm_map[i, 2] - lm_map[i, 0], lm_map[i, 3] - lm_map[i, 1]) > 0.0:
            landmark_terms += 2
        for e in range(2):
            if point_ok[i, e]:
                landmark_terms += 1
    if poses.shape[0] > 0:
        landmarks = pose_cost(
            poses[0, 0],
            poses[0, 1],
            poses[0, 2],
            lm_view,
            lm_map,
            point_ok,
            points[:0],
            ref,
            boxes,
            line_sigma,
            point_sigma,
            scan_sigma,
            huber,
            gate,
            overhang,
            np.inf,
        )
        total = landmarks
        matched = landmarks
        c = math.cos(poses[0, 2])
        s = math.sin(poses[0, 2])
        for p in range(points.shape[0]):
            tx = poses[0, 0] + c * points[p, 0] - s * points[p, 1]
            ty = poses[0, 1] + s * points[p, 0] + c * points[p, 1]
            found, distance = nearest_surface(tx, ty, ref, boxes, gate, overhang)
            cost = huber_cost(distance / scan_sigma, huber)
            total += cost
            if found >= 0:
                per_surface[found] += 1
                matched += cost
        costs[0] = total
    terms, independent = effective_terms(landmark_terms, per_surface)
    return costs, per_surface, matched, terms, independent


@dataclass(frozen=True, slots=True)
class Ambiguity:
    """The outcome of :func:`likelihood_ratio` for one view."""

    statistic: float  # 2 (cost at the prediction - cost at the fit) / residual variance, per independent term
    threshold: float  # the chi-square(dof) quantile it is compared with
    ambiguous: bool  # the view does not refute the prediction: keep the odometry


#: Degrees of freedom of the likelihood ratio: the pose's x, y and heading.
DOF = 3


def threshold(probability: float, dof: int = DOF) -> float:
    """The chi-square(``dof``) quantile ``probability`` (0 when the test is off); computed once per mapper.

    scipy is imported here, not per view: the import statement alone costs
    about 0.1 ms a call (``docs/albot1-mapper.md``, "Kernels").
    """
    if probability <= 0.0:
        return 0.0
    from scipy.stats import chi2  # noqa: PLC0415  (only when the test is on)

    return float(chi2.ppf(probability, dof))


def likelihood_ratio(
    fit_cost: float,
    predicted_cost: float,
    matched_cost: float,
    terms: int,
    independent: int,
    limit: float,
    dof: int = DOF,
) -> Ambiguity:
    """Whether the odometry's prediction explains the view about as well as the fit (see the module docstring).

    ``fit_cost`` / ``predicted_cost``: the robust costs at the two poses;
    ``matched_cost``: the fit's cost over its ``terms`` associated residual
    terms, of which ``independent`` are independent. The residual variance
    (in sigmas squared) is ``2 matched_cost / (terms - dof)``; the cost
    difference is scaled by ``independent / terms`` (correlated terms carry
    less information than their number says) and compared with ``limit``
    (:func:`threshold`). With no more terms than degrees of freedom the view
    cannot refute anything: ambiguous.
    """
    if terms <= dof or independent <= 0:
        return Ambiguity(0.0, limit, True)
    variance = max(2.0 * matched_cost / (terms - dof), 1e-12)
    statistic = 2.0 * max(predicted_cost - fit_cost, 0.0) / variance * (independent / terms)
    return Ambiguity(statistic, limit, statistic <= limit)


def view_ambiguity(
    kernels_costs: object,
    fitted: Pose,
    predicted: Pose,
    lm_view: FloatArray,
    lm_map: FloatArray,
    point_ok: NDArray[np.bool_],
    points: FloatArray,
    ref: FloatArray,
    sigmas: tuple[float, float, float, float, float],
    limit: float,
    overhang: float = NO_LIMIT,
) -> Ambiguity:
    """:func:`likelihood_ratio` of one view: costs by ``kernels_costs`` (:func:`measurement_costs`, compiled or not).

    ``sigmas``: line, point and scan sigma, Huber threshold (in sigmas) and
    the scan gate, as the fit used them; ``limit``: :func:`threshold`;
    ``overhang``: the overlap rule the fit used (:mod:`albot1.methods.albot1.mapping.overlap`).
    """
    poses = np.array([fitted, predicted], dtype=float)
    costs, _, matched, terms, independent = kernels_costs(  # type: ignore[operator]
        poses, lm_view, lm_map, point_ok, points, ref, *sigmas, overhang
    )
    return likelihood_ratio(float(costs[0]), float(costs[1]), float(matched), int(terms), int(independent), limit)
