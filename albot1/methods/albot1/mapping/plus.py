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
   featureless corridors;
5. with ``degenerate_sd_m`` / ``gate_probability``,
   :func:`screen_measurement` keeps the odometry's component along the
   directions the fit does not fix, and rejects a fit that disagrees with the
   odometry beyond their stated uncertainties.
6. with ``ambiguity_probability``, :mod:`.ambiguity` evaluates the view's own
   robust cost at the odometry's prediction: where the view does not refute
   it (a likelihood ratio below that chi-square quantile), the prediction is
   the pose and the fusion is skipped.
7. with ``scan_overlap = "surface"``, :mod:`.overlap` matches a view point
   to an update-view surface only where its projection falls on that
   surface (up to ``scan_overhang_m`` beyond its ends).
8. with ``window_updates`` (and the ambiguity test on), :mod:`.window` first
   tests the odometry since the oldest of the last ``window_updates`` update
   views against that view's surfaces: not refuted, the odometry over the
   window is the pose (false alarms and the fit's bias in the anchors between
   are dropped).
9. with ``turn_bound_floor_deg``, :mod:`.turn_bound` refits a view no landmark places from its near starts
   when it turns the robot further than its odometry did on weak evidence.
10. with ``view_noise_learning_rate``, :mod:`.view_noise` takes the views' own scatter out of the odometry learner's
    samples. With ``consistent_information`` (off in ``plus``), :mod:`.consistency` scales the fit's information down
    to what the ambiguity test's likelihood ratio says the view knows, before the fusion. With ``fit_noise`` (off in
    ``plus``), :mod:`.fit_noise` adds the view noise to a fused fit's covariance; with ``fit_noise_source = "cross"``
    (off) the scatter it adds is learnt instead from the view's fit against the update view before the last
    (:meth:`.ViewNoise.learn_cross`), a disagreement that holds no odometry.
11. with ``mount_prior_m`` (off in ``plus``), :mod:`.mount` learns the odometry-to-scanner mount and corrects the
    odometry's increments (only while it explains half the disagreement, headings counted); with
    ``kept_views_teach`` (on in ``plus``), the ambiguity test's kept views also teach
    the learner, so its samples are not only the views that refute the odometry.
12. with ``refutation_probability`` (off), :mod:`.refutation` keeps the prediction where the view noise explains the
    fit's departure; with ``noise_split_samples`` (off), :mod:`.noise_split` learns the odometry's spread and the views'
    own as the slope and intercept of the disagreement against the motion since the update.

The per-scan loop is :func:`albot1.methods.albot1.mapping.pose_kernels.refine_pose`
(numba or plain Python, same bits); this module prepares its inputs, learns
the odometry noise and fuses the prior (a few 3x3 products per scan).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import Pose, between_pose, compose_pose, wrap_angle
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.mapping.ambiguity import Ambiguity, likelihood_ratio, threshold, view_ambiguity
from albot1.methods.albot1.mapping.consistency import information_scale, stated_distance
from albot1.methods.albot1.mapping.cross_noise import CrossFit, fixes
from albot1.methods.albot1.mapping.fit_noise import fit_noise_factor, with_fit_noise
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.mount import MountCalibration
from albot1.methods.albot1.mapping.noise_split import NoiseSplit
from albot1.methods.albot1.mapping.plus_params import PlusParams
from albot1.methods.albot1.mapping.refutation import refutes
from albot1.methods.albot1.mapping.screen import screen_measurement
from albot1.methods.albot1.mapping.start_poses import start_poses
from albot1.methods.albot1.mapping.turn_bound import allowance, beyond, bounded_starts
from albot1.methods.albot1.mapping.view_noise import START, ViewNoise, median_step
from albot1.methods.albot1.mapping.window import OdometryWindow, UpdateRecord, WindowOutcome
from albot1.methods.albot1.perception.endpoints import STABLE

#: The odometry learner's fixed choices (``docs/albot1-mapper.md``, "Albot1+"): a view teaches it only when its
#: measurement alone fixes the position to better than 5 cm and the heading to better than 0.05 rad (information
#: above 400 per m^2 and per rad^2: :func:`.cross_noise.fixes`) after at least 5 cm of motion since the update.
LEARN_MIN_MOTION_M = 0.05
#: Variance floors of the prior (m^2, rad^2): odometry is never trusted below 1 cm and 1 mrad.
PRIOR_FLOOR = (1e-4, 1e-6)


class OdometryNoise:
    """How far the odometry since the last update can be trusted, learnt from the views (``adaptive`` prior).

    Modelled as a random walk: the odometry's prediction after motion ``s``
    since the update (metres, a turn counting ``m_per_rad`` per radian) is
    off by a zero-mean error of variance ``q * s`` per position axis and in
    heading. At every view whose measurement fixes the pose well on its own,
    the disagreement ``nu`` between the measured and predicted pose gives a
    sample ``nu^2 / s`` of ``q`` times a chi-square(1) variable; ``q``
    tracks the running *median* of these samples (divided by the
    chi-square(1) median), by multiplicative steps of ``exp(+-2 *
    learning_rate)`` up or down. The median, unlike a mean, is not moved by
    the occasional mismatched view. ``nu`` also holds the measurement's own
    error, so ``q`` errs on the side of distrusting the odometry: with
    perfect odometry it settles at the measurement's error and the two are
    weighted about equally. Starting values: the fixed-prior fields.
    """

    def __init__(self, params: PlusParams) -> None:
        self.params = params
        self.q = [params.xy_per_sqrt_m**2, params.rad_per_sqrt_m**2]
        self.samples = 0

    def learn(self, nu2_xy: float, nu2_phi: float, motion: float) -> None:
        """One view's squared disagreement (per position axis, m^2; heading, rad^2) after ``motion``."""
        self.samples += 1
        step = 2.0 * self.params.learning_rate
        for g, nu2 in ((0, nu2_xy), (1, nu2_phi)):
            self.q[g] = max(median_step(self.q[g], nu2 / motion, step), 1e-12)

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
        self.noise: OdometryNoise | NoiseSplit = OdometryNoise(params)
        self.view_noise = ViewNoise(params.view_noise_rate) if params.view_noise_rate > 0.0 else None  # .view_noise
        #: The views' own variance and the odometry's from one line (:mod:`.noise_split`): it replaces both learners.
        self.split = (
            NoiseSplit(params.noise_split, (self.noise.q[0], self.noise.q[1]), START, PRIOR_FLOOR)
            if params.noise_split > 0
            else None
        )
        if self.split is not None:
            self.noise, self.view_noise = self.split, None
        #: The fit noise's scatter from two fits of a view against two update views (:mod:`.cross_noise`).
        self.cross = (
            CrossFit(params, kernels.refine_pose) if params.cross_fit_noise and self.view_noise is not None else None
        )
        mount = params.mount_prior
        self.mount = MountCalibration(mount, params.m_per_rad) if mount > 0.0 else None  # :mod:`.mount`
        self._odometry_since: Pose = (0.0, 0.0, 0.0)  # the odometry's own increment, which the mount learns from
        #: Views whose fit left at least one direction to the odometry, and views rejected for the odometry.
        self.degenerate_views = 0
        self.gate_rejections = 0
        #: Views whose own terms did not refute the odometry's prediction (:mod:`.ambiguity`), and the last test.
        self.ambiguous_views = 0
        self.last_ambiguity: Ambiguity | None = None
        self._ambiguity_limit = threshold(params.ambiguity_probability)
        #: Views the ambiguity test let through whose departure the view noise explains (:mod:`.refutation`).
        self.unrefuted_views = 0
        self._refutation_limit = threshold(params.refutation_probability) if self.view_noise is not None else 0.0
        #: The fit's sigmas as the ambiguity tests take them (built once, not per view).
        self._sigmas = (params.line_sigma, params.point_sigma, params.scan_sigma, params.huber, params.scan_gate)
        #: Fits without a prior are scored in the same kernel call for the ambiguity test (:meth:`_solve`).
        self._score_fits = params.prior == "adaptive" and params.ambiguity_probability > 0.0
        self._scored: tuple[Pose, Pose, float, float, float, int, int] | None = None
        #: The window test (:mod:`.window`; only with the ambiguity test), its kept views and its last outcome.
        self.window = (
            OdometryWindow(params.window_updates, params.motion_model)
            if params.window_updates >= 2 and params.ambiguity_probability > 0.0
            else None
        )
        self.window_views = 0
        self._window_limit = threshold(params.window_probability) if self.window is not None else 0.0
        self.last_window: WindowOutcome | None = None
        #: Views no landmark placed refitted from their near starts by the turn bound (:mod:`.turn_bound`).
        self.turn_bounded_views = 0

    def reset(self, view_map: FloatArray, pose: Pose, odometry: Pose | None = None) -> None:
        """A map update placed a view at ``pose``; ``view_map`` are its surfaces in the map (the new reference).

        ``odometry``: the view's own odometry (REP-103), which the window test measures motion from.
        """
        if self.cross is not None:
            self.cross.reset(self._ref)
        self._ref = np.ascontiguousarray(view_map, dtype=float).reshape(-1, 4)
        self._anchor = pose
        if self.window is not None and odometry is not None:
            self.window.add(UpdateRecord(pose, odometry, self._ref))

    def pose(
        self,
        starts: FloatArray,
        lm_view: FloatArray,
        lm_map: FloatArray,
        lm_kinds: tuple[NDArray[np.int64], NDArray[np.int64]],
        points: FloatArray,
        since_update: Pose,
        odometry: Pose | None = None,
        placed: bool = True,
    ) -> Pose:
        """The pose of a view, from the cheapest of ``starts`` ``(c, 3)`` (candidate poses; see the mapper).

        ``lm_view`` / ``lm_map`` ``(k, 4)``: recognised landmarks and their
        map copies; ``lm_kinds``: their endpoint labels now and in the map;
        ``points``: the scan's (:func:`~.step_kernels.perceive`); ``since_update``: the odometry
        motion since the last update view (thesis frame); ``odometry``: the
        view's own odometry (REP-103; the window test's); ``placed``: a
        landmark placed the robot (False: the turn bound applies).
        """
        ok = np.ascontiguousarray(STABLE[lm_kinds[0]] & STABLE[lm_kinds[1]]).reshape(-1, 2)
        return self.pose_stable(starts, lm_view, lm_map, ok, points, since_update, odometry, placed)

    def pose_stable(
        self,
        starts: FloatArray,
        lm_view: FloatArray,
        lm_map: FloatArray,
        ok: NDArray[np.bool_],
        points: FloatArray,
        since_update: Pose,
        odometry: Pose | None = None,
        placed: bool = True,
    ) -> Pose:
        """:meth:`pose` given which endpoints ``ok`` ``(k, 2)`` are stable now and in the map (C-contiguous).

        The mapper's kernel (:func:`~.localise_kernels.robust_starts`) computes ``ok`` with the landmark rows.
        """
        p = self.params
        if self.mount is not None:  # the scanner's increment, not the odometry frame's (:mod:`.mount`)
            self._odometry_since, since_update = since_update, self.mount.correct(since_update)
        predicted = compose_pose(self._anchor, since_update)
        if p.prior == "fixed":
            motion = self._motion(since_update)
            v_xy = PRIOR_FLOOR[0] + p.xy_per_sqrt_m**2 * motion
            v_phi = PRIOR_FLOOR[1] + p.rad_per_sqrt_m**2 * motion
            return self._solve(starts, lm_view, lm_map, ok, points, predicted, 1.0 / v_xy, 1.0 / v_phi)[0]
        measured, info = self._solve(starts, lm_view, lm_map, ok, points, predicted, 0.0, 0.0)
        if p.prior == "off":
            return measured
        if self.cross is not None and self._motion(since_update) > LEARN_MIN_MOTION_M:
            self.cross.learn(measured, info, points)
        sigmas = self._sigmas
        #: The turn bound's test of ``measured`` (limit 0), reused by the ambiguity test while ``measured`` stands.
        support: Ambiguity | None = None
        if not placed and p.turn_floor > 0.0:  # the turn bound (:mod:`.turn_bound`); views a landmark placed skip it
            limit = allowance(p.turn_floor, p.turn_scale, since_update[2])
            if beyond(measured[2] - predicted[2], limit):
                support = self._ambiguity(measured, predicted, lm_view, lm_map, ok, points, 0.0)
                if support.statistic <= p.turn_statistic:
                    self.turn_bounded_views += 1
                    # around the prediction the allowance is measured from, not the first start (the previous
                    # view's pose composed with the step: between updates the two differ)
                    near = bounded_starts(start_poses(predicted, None, None), limit)
                    measured, info = self._solve(near, lm_view, lm_map, ok, points, predicted, 0.0, 0.0)
                    support = None  # a new fit: the ambiguity test measures it afresh
                    if beyond(measured[2] - predicted[2], limit):
                        return predicted
        if p.ambiguity_probability > 0.0:
            if self.window is not None and odometry is not None:
                window = self.window.test(
                    odometry,
                    measured,
                    points,
                    self._k.refine_pose,
                    self._k.measurement_costs,
                    sigmas,
                    p.iterations,
                    self._window_limit,
                    p.overhang,
                )
                self.last_window = window
                if window is not None and window.kept:
                    self.window_views += 1
                    return window.prediction
            if support is not None:  # same poses, terms and sigmas: the statistic does not depend on the limit
                bound = self._ambiguity_limit
                test = Ambiguity(support.statistic, bound, support.statistic <= bound)
            else:
                test = self._ambiguity(measured, predicted, lm_view, lm_map, ok, points, self._ambiguity_limit)
            self.last_ambiguity = test
            if test.ambiguous:
                self.ambiguous_views += 1
                if self.view_noise is not None:
                    self.view_noise.learn(measured, predicted)
                if p.kept_views_teach:  # samples not selected by their size (docs: "Kept views teach, adopted")
                    self._learn(measured, info.tolist(), predicted, self._motion(since_update))
                return predicted
            if self._refutation_limit > 0.0 and self.view_noise is not None:  # :mod:`.refutation`
                rows = info.tolist()
                if not refutes(measured, rows, predicted, self.view_noise.variance, self._refutation_limit):
                    self.unrefuted_views += 1
                    self._learn(measured, rows, predicted, self._motion(since_update))
                    return predicted
            if p.consistency > 0.0:  # :mod:`.consistency`: weigh the fit by what its own cost says it knows
                scale = information_scale(test.statistic, stated_distance(info, measured, predicted), p.consistency)
                return self._fuse(measured, info, predicted, self._motion(since_update), scale, test.statistic)
            return self._fuse(measured, info, predicted, self._motion(since_update), 1.0, test.statistic)
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
        if self._score_fits and info_xy == 0.0 and info_phi == 0.0:  # the ambiguity test scores this fit next
            line, point, scan, huber, gate = self._sigmas
            x, y, phi, info, fit_cost, predicted_cost, matched, terms, independent = self._k.refine_and_score(
                starts,
                lm_view,
                lm_map,
                ok,
                points,
                self._ref,
                *prior,
                line,
                point,
                scan,
                huber,
                gate,
                p.iterations,
                p.overhang,
            )  # one kernel call, not two (.step_kernels)
            pose = (x, y, phi)
            self._scored = (pose, prior, fit_cost, predicted_cost, matched, terms, independent)
            return pose, info
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
            p.overhang,
        )
        return (x, y, phi), info

    def _ambiguity(
        self,
        measured: Pose,
        predicted: Pose,
        lm_view: FloatArray,
        lm_map: FloatArray,
        ok: NDArray[np.bool_],
        points: FloatArray,
        limit: float,
    ) -> Ambiguity:
        """The ambiguity test of ``measured`` against ``predicted`` (:mod:`.ambiguity`) at ``limit``.

        One place for the turn bound's test (limit 0) and the ambiguity test's, which must score the same terms
        with the same sigmas so that the turn bound's statistic can stand in for the second.
        """
        scored = self._scored  # the fit's own costs, computed with it (:meth:`_solve`), when it is this fit
        if scored is not None and scored[0] is measured and scored[1] is predicted:
            return likelihood_ratio(*scored[2:], limit)
        return view_ambiguity(
            self._k.measurement_costs,
            measured,
            predicted,
            lm_view,
            lm_map,
            ok,
            points,
            self._ref,
            self._sigmas,
            limit,
            self.params.overhang,
        )

    def _learn(self, measured: Pose, rows: list[list[float]], predicted: Pose, motion: float) -> float:
        """Teach the odometry learner this view's disagreement with the prediction; return the heading difference.

        Only a view whose fit fixes every direction (``rows``: its 3x3 information as nested lists) after enough
        motion teaches: elsewhere the disagreement is the fit's slack, not the odometry's error. Kept views (the
        ambiguity test's, with ``kept_views_teach``) come here without the fusion that follows for fused views.
        """
        d_phi = wrap_angle(measured[2] - predicted[2])
        if motion > LEARN_MIN_MOTION_M and fixes(rows):
            nu2_xy = 0.5 * ((measured[0] - predicted[0]) ** 2 + (measured[1] - predicted[1]) ** 2)
            nu2_phi = d_phi * d_phi
            if self.view_noise is not None:  # the odometry's share of the disagreement (:mod:`.view_noise`)
                nu2_xy, nu2_phi = self.view_noise.remove(nu2_xy, nu2_phi)
            if self.mount is not None:
                weight = 1.0 / self.noise.prior_variance(motion)[0]
                self.mount.learn(self._odometry_since, between_pose(self._anchor, measured), weight)
            self.noise.learn(nu2_xy, nu2_phi, motion)
        return d_phi

    def _fuse(self, measured: Pose, info: FloatArray, predicted: Pose, motion: float, scale: float = 1.0,
              statistic: float = 0.0) -> Pose:  # fmt: skip
        """Learn from this view, then combine the measured and predicted poses by their information.

        ``scale`` (:mod:`.consistency`) multiplies the measurement's information in the combination only;
        ``statistic`` (the ambiguity test's) sets how much of the fit's scatter :mod:`.fit_noise` adds to it.

        The measurement's information is the solver's (``info``, 3x3), the
        prediction's the inverse of :meth:`OdometryNoise.prior_variance`
        (diagonal): the combination is ``(I_m + I_p)^-1 (I_m m + I_p p)``,
        written out for 3x3 symmetric matrices (numpy's per-call overhead
        would cost more than the arithmetic).
        """
        # One conversion to Python floats (the same values as six ``float(info[i, j])``).
        rows = info.tolist()
        (h00, h01, h02), (_, h11, h12), (_, _, h22) = rows
        d_phi = self._learn(measured, rows, predicted, motion)
        v_xy, v_phi = self.noise.prior_variance(motion)
        if self.params.degenerate_sd > 0.0 or self.params.gate_probability > 0.0:
            screened = screen_measurement(
                measured, info, predicted, (v_xy, v_phi), self.params, self._k.screen_directions
            )
            if screened.degenerate:
                self.degenerate_views += 1
            if screened.rejected:
                self.gate_rejections += 1
                return predicted
            measured, info = screened.pose, screened.info
            (h00, h01, h02), (_, h11, h12), (_, _, h22) = info.tolist()
            d_phi = wrap_angle(measured[2] - predicted[2])
        if scale != 1.0:  # after learning and the screen, which judge the fit by its stated information
            h00, h01, h02, h11, h12, h22 = h00 * scale, h01 * scale, h02 * scale, h11 * scale, h12 * scale, h22 * scale
        if self.split is not None:  # the views' own variance from the noise split (:mod:`.noise_split`)
            h00, h01, h02, h11, h12, h22 = with_fit_noise((h00, h01, h02, h11, h12, h22), self.split.variance, 1.0)
        elif self.params.fit_noise > 0.0 and self.view_noise is not None:  # its measured scatter (:mod:`.fit_noise`)
            f = fit_noise_factor(self.params.fit_noise, statistic, self.params.fit_noise_statistic)
            scatter = (self.view_noise if self.cross is None else self.cross.noise).variance
            h00, h01, h02, h11, h12, h22 = with_fit_noise((h00, h01, h02, h11, h12, h22), scatter, f)
        p_xy, p_phi = 1.0 / v_xy, 1.0 / v_phi
        # The prediction's heading unwrapped next to the measured one, so the average does not jump by 2 pi.
        t0, t1, t2 = predicted[0], predicted[1], measured[2] - d_phi
        a00, a11, a22 = h00 + p_xy, h11 + p_xy, h22 + p_phi
        r0 = h00 * measured[0] + h01 * measured[1] + h02 * measured[2] + p_xy * t0
        r1 = h01 * measured[0] + h11 * measured[1] + h12 * measured[2] + p_xy * t1
        r2 = h02 * measured[0] + h12 * measured[1] + h22 * measured[2] + p_phi * t2
        c00 = a11 * a22 - h12 * h12
        c01 = h02 * h12 - h01 * a22
        c02 = h01 * h12 - h02 * a11
        det = a00 * c00 + h01 * c01 + h02 * c02
        c11 = a00 * a22 - h02 * h02
        c12 = h01 * h02 - a00 * h12
        c22 = a00 * a11 - h01 * h01
        x = (c00 * r0 + c01 * r1 + c02 * r2) / det
        y = (c01 * r0 + c11 * r1 + c12 * r2) / det
        phi = (c02 * r0 + c12 * r1 + c22 * r2) / det
        return (x, y, wrap_angle(phi))
