"""Albot1+ (``--preset plus``): the same perceptual map, a pose that does not drift as fast.

Albot1 places the robot by one landmark (Algorithm 2): the best-ranked
recognised landmark's reference point and direction are laid onto its map
copy, and nothing averages out that one landmark's error. Every map update
then freezes the pose error of its view into the map, so the errors of
successive updates add up (``docs/albot1-mapper.md``, "Albot1+", has the
measurements). Albot1+ keeps the paradigm -- a transient map of line
surfaces, landmarks tracked from view to view, updates only when fewer than
``min_landmarks`` remain, no global back-end -- and changes only how a
pose is computed:

1. start from the thesis's single-landmark pose (odometry when no landmark
   is usable);
2. robust least squares over *all* recognised landmarks: point-to-line
   terms on every endpoint, point-to-point terms on the endpoints stable in
   both views, Huber weights (``robust_*`` fields);
3. with ``scan_refinement``, the view's points against the surfaces of the
   last update view, point-to-line (``scan_*``): matching against the
   transient map only, and with the landmark point terms in the same
   problem so the pose cannot slide along a corridor;
4. with ``odometry_prior``, the odometry since the last update as a prior
   whose variance grows with the motion since that update (``prior_*``):
   ``fixed`` uses the configured growth; ``adaptive`` learns it online from
   how far the odometry and the view disagree (:class:`OdometryNoise`), so
   bad odometry is out-voted and good odometry carries the robot through
   featureless corridors.

The per-scan loop is :func:`albot1.methods.albot1.mapping.pose_kernels.refine_pose`
(numba or plain Python, same bits); this module prepares its inputs, learns
the odometry noise and fuses the prior (a few 3x3 products per scan).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import Pose, compose_pose, wrap_angle
from albot1.methods.albot1.mapping.accel import MappingKernels
from albot1.methods.albot1.perception.endpoints import STABLE

FloatArray = NDArray[np.float64]

#: The odometry learner's fixed choices (``docs/albot1-mapper.md``, "Albot1+"): a view teaches it only when its
#: measurement alone fixes the position to better than 5 cm and the heading to better than 0.05 rad (information
#: above 400 per m^2 / per rad^2) after at least 5 cm of motion since the update...
LEARN_MIN_INFO = 400.0
LEARN_MIN_MOTION_M = 0.05
#: ... one disagreement counts at most this many times its expected square (robust to a mis-association) ...
LEARN_CLIP = 9.0
#: ... the first views are averaged equally, as if this many had already agreed with the starting values ...
LEARN_PRIOR_COUNT = 5
#: ... and the measurement's own variance is never believed smaller than the one its weights imply; it starts at
#: four times that (a view's errors are correlated, so its weights overstate what it knows).
MEASUREMENT_SCALE_MIN = 1.0
MEASUREMENT_SCALE_START = 4.0
#: Variance floors of the prior (m^2, rad^2): odometry is never trusted below 1 cm and 1 mrad.
PRIOR_FLOOR = (1e-4, 1e-6)


@dataclass(frozen=True, slots=True)
class PlusParams:
    """The Albot1+ fields of :class:`~albot1.methods.albot1.mapping.config.Albot1Config`, in SI units."""

    line_sigma: float
    point_sigma: float
    huber: float
    iterations: int
    scan_refinement: bool
    scan_sigma: float
    scan_gate: float
    scan_stride: int
    prior: str  # off | fixed | adaptive
    xy_per_sqrt_m: float  # m per sqrt(m of motion)
    rad_per_sqrt_m: float  # rad per sqrt(m of motion)
    m_per_rad: float  # a turn of 1 rad counts as this much motion
    learning_rate: float


class OdometryNoise:
    """How far the odometry since the last update can be trusted, learnt from the views (``adaptive`` prior).

    At every view whose measurement fixes the pose well on its own, the
    squared disagreement ``nu^2`` between the measured pose and the
    odometry's prediction is modelled, per group (position, heading), as

        E[nu^2] = kappa * v_meas + q * s

    where ``v_meas`` is the variance the measurement's weights imply
    (from its information matrix), ``kappa`` corrects it (weights are
    rarely exact), ``s`` is the motion since the update (metres, turns
    counted ``m_per_rad`` per radian) and ``q`` the odometry's variance per
    unit of motion. Measurement errors do not grow with ``s``, odometry
    errors do, so the two are separable: ``kappa`` and ``q`` are the
    weighted least-squares fit of this line to the views seen so far
    (exponentially forgetting at ``learning_rate``), each sample weighted by
    its inverse expected variance squared and clipped at
    :data:`LEARN_CLIP` times it. Starting values: ``kappa`` =
    :data:`MEASUREMENT_SCALE_START` and ``q`` from the fixed-prior fields.
    """

    def __init__(self, params: PlusParams) -> None:
        self.params = params
        self.kappa = [MEASUREMENT_SCALE_START, MEASUREMENT_SCALE_START]
        self.q = [params.xy_per_sqrt_m**2, params.rad_per_sqrt_m**2]
        self._normal = [np.zeros((2, 2)), np.zeros((2, 2))]
        self._rhs = [np.zeros(2), np.zeros(2)]
        self.samples = 0

    def learn_median(self, nu2: tuple[float, float], motion: float) -> None:
        """EXPERIMENT: track the median of nu^2 / motion (a chi-square(1) median is 0.455 of its mean)."""
        self.samples += 1
        for g in range(2):
            x = nu2[g] / motion
            step = self.params.learning_rate * 2.0
            if x > 0.455 * self.q[g]:
                self.q[g] *= math.exp(step)
            else:
                self.q[g] *= math.exp(-step)
        self.kappa = [1.0, 1.0]

    def learn(self, nu2: tuple[float, float], v_meas: tuple[float, float], motion: float) -> None:
        """One view's squared disagreement ``nu2`` and implied measurement variance ``v_meas``, per group."""
        self.samples += 1
        rate = max(self.params.learning_rate, 1.0 / (self.samples + LEARN_PRIOR_COUNT))
        for g in range(2):
            expected = self.kappa[g] * v_meas[g] + self.q[g] * motion + PRIOR_FLOOR[g]
            sample = min(nu2[g], LEARN_CLIP * expected)
            weight = 1.0 / (expected * expected)
            row = np.array([v_meas[g], motion])
            self._normal[g] = (1.0 - rate) * self._normal[g] + rate * weight * np.outer(row, row)
            self._rhs[g] = (1.0 - rate) * self._rhs[g] + rate * weight * sample * row
            normal = self._normal[g]
            det = normal[0, 0] * normal[1, 1] - normal[0, 1] * normal[1, 0]
            if det <= 1e-12 * (normal[0, 0] * normal[1, 1] + 1e-300):
                continue  # every sample so far had the same mix of measurement and motion: not separable yet
            kappa = (self._rhs[g][0] * normal[1, 1] - self._rhs[g][1] * normal[0, 1]) / det
            q = (self._rhs[g][1] * normal[0, 0] - self._rhs[g][0] * normal[1, 0]) / det
            self.kappa[g] = max(MEASUREMENT_SCALE_MIN, float(kappa))
            self.q[g] = max(0.0, float(q))

    def prior_variance(self, motion: float) -> tuple[float, float]:
        """Variance (m^2 per axis, rad^2) of the odometry's prediction after ``motion`` since the update."""
        return (PRIOR_FLOOR[0] + self.q[0] * motion, PRIOR_FLOOR[1] + self.q[1] * motion)


class PlusLocaliser:
    """Computes Albot1+ poses against the last update view (see the module docstring)."""

    def __init__(self, params: PlusParams, kernels: MappingKernels, max_range: float) -> None:
        self.params = params
        self._k = kernels
        self._max_range = max_range
        self._ref = np.empty((0, 4))
        self._anchor: Pose = (0.0, 0.0, 0.0)
        self.noise = OdometryNoise(params)

    def reset(self, view_map: FloatArray, pose: Pose) -> None:
        """A map update placed a view at ``pose``; ``view_map`` are its surfaces in the map (the new reference)."""
        self._ref = np.ascontiguousarray(view_map, dtype=float).reshape(-1, 4)
        self._anchor = pose

    def scan_points(self, ranges: FloatArray, angles: FloatArray) -> FloatArray:
        """Every ``scan_stride``-th return within ``max_range``, thesis frame (none without scan refinement)."""
        if not self.params.scan_refinement:
            return np.empty((0, 2))
        r = np.asarray(ranges, dtype=float)
        a = np.asarray(angles, dtype=float)
        keep = np.flatnonzero(np.isfinite(r) & (r > 0.0) & (r <= self._max_range))[:: self.params.scan_stride]
        return np.ascontiguousarray(np.column_stack([-r[keep] * np.sin(a[keep]), r[keep] * np.cos(a[keep])]))

    def pose(
        self,
        starts: FloatArray,
        lm_view: FloatArray,
        lm_map: FloatArray,
        lm_kinds: tuple[NDArray[np.int64], NDArray[np.int64]],
        points: FloatArray,
        since_update: Pose,
    ) -> Pose:
        """The pose of a view, from the cheapest of ``starts`` ``(c, 3)`` (candidate poses; see the mapper).

        ``lm_view`` / ``lm_map`` ``(k, 4)``: recognised landmarks and their
        map copies; ``lm_kinds``: their endpoint labels now and in the map;
        ``points``: :meth:`scan_points`; ``since_update``: the odometry
        motion since the last update view (thesis frame).
        """
        p = self.params
        ok = np.ascontiguousarray(STABLE[lm_kinds[0]] & STABLE[lm_kinds[1]]).reshape(-1, 2)
        predicted = compose_pose(self._anchor, since_update)
        if p.prior == "fixed":
            motion = self._motion(since_update)
            v_xy = PRIOR_FLOOR[0] + p.xy_per_sqrt_m**2 * motion
            v_phi = PRIOR_FLOOR[1] + p.rad_per_sqrt_m**2 * motion
            return self._solve(starts, lm_view, lm_map, ok, points, predicted, 1.0 / v_xy, 1.0 / v_phi)[0]
        measured, info = self._solve(starts, lm_view, lm_map, ok, points, predicted, 0.0, 0.0)
        if p.prior == "off":
            return measured
        return self._fuse(measured, info, predicted, self._motion(since_update))

    def _motion(self, since_update: Pose) -> float:
        return math.hypot(since_update[0], since_update[1]) + self.params.m_per_rad * abs(since_update[2])

    def _solve(
        self,
        starts: FloatArray,
        lm_view: FloatArray,
        lm_map: FloatArray,
        ok: NDArray[np.bool_],
        points: FloatArray,
        prior: Pose,
        info_xy: float,
        info_phi: float,
    ) -> tuple[Pose, FloatArray]:
        p = self.params
        x, y, phi, info = self._k.refine_pose(
            starts,
            lm_view,
            lm_map,
            ok,
            points,
            self._ref,
            prior[0],
            prior[1],
            prior[2],
            info_xy,
            info_phi,
            p.line_sigma,
            p.point_sigma,
            p.scan_sigma,
            p.huber,
            p.scan_gate,
            p.iterations,
        )
        return (x, y, phi), info

    def _fuse(self, measured: Pose, info: FloatArray, predicted: Pose, motion: float) -> Pose:
        """Learn from this view, then combine the measured and predicted poses by their information."""
        noise = self.noise
        cov = np.linalg.pinv(info + np.eye(3) * 1e-9)
        v_meas = (0.5 * (cov[0, 0] + cov[1, 1]), cov[2, 2])
        d_phi = wrap_angle(measured[2] - predicted[2])
        nu2 = (0.5 * ((measured[0] - predicted[0]) ** 2 + (measured[1] - predicted[1]) ** 2), d_phi * d_phi)
        well_fixed = np.linalg.eigvalsh(info[:2, :2])[0] > LEARN_MIN_INFO and info[2, 2] > LEARN_MIN_INFO
        if well_fixed and motion > LEARN_MIN_MOTION_M:
            if self.params.m_per_rad < 0.99:
                noise.learn_median(nu2, motion)
            else:
                noise.learn(nu2, v_meas, motion)
        scale = np.sqrt(np.array([noise.kappa[0], noise.kappa[0], noise.kappa[1]]))
        info_meas = info / np.outer(scale, scale)
        v_xy, v_phi = noise.prior_variance(motion)
        info_prior = np.diag([1.0 / v_xy, 1.0 / v_xy, 1.0 / v_phi])
        m = np.array(measured)
        target = np.array([predicted[0], predicted[1], measured[2] - d_phi])  # the prediction's heading, unwrapped
        fused = np.linalg.solve(info_meas + info_prior, info_meas @ m + info_prior @ target)
        return (float(fused[0]), float(fused[1]), wrap_angle(float(fused[2])))
