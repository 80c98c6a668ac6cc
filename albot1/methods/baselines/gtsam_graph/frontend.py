"""The front end of :class:`~albot1.methods.baselines.gtsam_graph.mapper.GtsamGraphMapper`: scan tracking.

Every scan is matched (point-to-line ICP, :mod:`.registration`) against the
local map of the newest nodes, from the odometry increment since the last
scan, or from the last tracked motion when the two disagree
(:meth:`FrontEnd.follow`). The tracked pose relative to the newest node says
when the robot moved far enough for a new node (:meth:`FrontEnd.moved_enough`),
and the tracking match becomes the new node's sequential edge, or the
odometry increment with a larger covariance when the match is poor
(:meth:`FrontEnd.sequential_edge`); with ``odometry_trust`` the odometry's heading
joins the graph as its own factor (or fused into the edge) where the
odometry has shown itself the better of the two (:mod:`.odometry_trust`). All of the tracking logic lives here; the
local map itself is the back end's (:meth:`.BackEnd.local_map`).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from albot1.data.model import Scan
from albot1.geometry import se2
from albot1.geometry.grid import first_per_cell
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.gtsam_graph.backend import BackEnd
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.earned_choice import EarnedFactors
from albot1.methods.baselines.gtsam_graph.gating import CorrectionScale, odometry_stalled, velocity_match_allowed
from albot1.methods.baselines.gtsam_graph.match_covariance import floor_covariance, shaped_covariance
from albot1.methods.baselines.gtsam_graph.odometry_runs import OdometryRuns
from albot1.methods.baselines.gtsam_graph.odometry_trust import OdometryFactor, OdometryFactors, OdometryTrust
from albot1.methods.baselines.gtsam_graph.registration import IcpParams, Registration, Target, try_register
from albot1.methods.baselines.gtsam_graph.span_edges import SpanEdge, span_guess, span_target_nodes
from albot1.methods.baselines.gtsam_graph.velocity_slide import slide_refused
from albot1.methods.baselines.gtsam_graph.velocity_time import elapsed, scaled_velocity


def preprocess(config: GtsamGraphConfig, scan: Scan, index: int) -> FloatArray:
    """Valid beams within the range limits, as points, thinned to one per ``scan_voxel_m`` cell."""
    ranges = np.asarray(scan.ranges, dtype=float)
    if np.isinf(ranges).any():
        raise BaselineError(f"gtsam-graph: scan {index}: ranges must be finite or NaN (no return), found inf")
    if not np.isfinite(np.asarray(scan.angles, dtype=float)).all():
        raise BaselineError(f"gtsam-graph: scan {index}: beam angles must be finite")
    pts = scan.points(config.min_range_m, config.max_range_m)
    cell = config.scan_voxel_m
    if cell > 0 and len(pts):
        pts = first_per_cell(pts, cell)
    return pts


class FrontEnd:
    """Scan-to-local-map tracking and the sequential edge of each new node."""

    def __init__(self, config: GtsamGraphConfig, back: BackEnd, counters: dict[str, int]) -> None:
        self.config = config
        self.counters = counters
        self._back = back
        self._seq_icp = config.icp(loop=False)
        self._track_icp = config.track_icp()
        self._seq_prior = np.diag(
            [config.odometry_sigma_xy_m**-2] * 2 + [math.radians(config.odometry_sigma_theta_deg) ** -2]
        )
        self._floor = config.match_floor()
        self._fallback = np.diag(
            [config.fallback_sigma_xy_m**2] * 2 + [math.radians(config.fallback_sigma_theta_deg) ** 2]
        )
        # The latest scan's pose in the frame of the newest node.
        self.track = np.zeros(3)
        # The last tracked scan-to-scan motion; None until a scan has been tracked: before that the velocity is
        # unknown, not zero (edmonton-corrected[::3] moves 3 m between its first scans, and a "standing still"
        # guess matched a corridor 3 m short and won because the odometry guess's match failed).
        self._velocity: FloatArray | None = None
        # Seconds the last tracked motion took, and since the previous scan (``track_velocity_time_scaled``; NaN:
        # unknown).
        self._velocity_dt = math.nan
        self._elapsed = math.nan
        # The previous scan's odometry increment (``track_velocity_only_after_stall``: a repeat there makes this scan
        # a catch-up step); None before the second scan.
        self._previous_increment: FloatArray | None = None
        self._corrections = CorrectionScale(
            config.track_outlier_window, config.match_sigma_floor_xy_m, config.match_sigma_floor_theta_deg
        )
        self._odometry_trust = OdometryTrust(
            config.odometry_trust_window,
            config.odometry_trust_bias_z,
            config.odometry_trust_gate_chi2,
            (0, 1, 2) if config.odometry_trust_translation else (2,),
            config.odometry_trust_bias_horizon,
            config.odometry_trust_min_variance_ratio,
            math.radians(config.odometry_trust_turn_deg),
            config.odometry_trust_kind_min_steps,
            math.radians(config.odometry_trust_floor_turn_deg),
            config.odometry_trust_turn_scale,
            config.odometry_trust_translation_follows_heading,
        )
        self._odometry_factors = (
            EarnedFactors(self._odometry_trust, config.odometry_trust_earned_level, counters)
            if config.odometry_trust_earned_level > 0
            else OdometryFactors(self._odometry_trust)
        )
        self._odometry_runs = (
            OdometryRuns(
                OdometryTrust(
                    config.odometry_trust_window,
                    config.odometry_trust_bias_z,
                    config.odometry_trust_gate_chi2,
                    (2,),
                    config.odometry_trust_bias_horizon,
                    config.odometry_trust_run_variance_ratio,
                ),
                config.odometry_trust_run_nodes,
                math.radians(config.odometry_trust_run_max_turn_deg),
            )
            if config.odometry_trust_run_nodes
            else None
        )
        # Odometry run factors judged at the latest node (``odometry_trust_run_nodes``), for the back end to add.
        self.run_factors: list[SpanEdge] = []
        # Odometry factors judged at the latest node (``odometry_trust_factors``), for the back end to add with it.
        self.odometry_factors: list[OdometryFactor] = []
        self.last_odometry: FloatArray | None = None
        # The previous scan's timestamp (s), set beside ``last_odometry``.
        self.last_stamp: float | None = None
        self._consecutive_fallbacks = 0

    def new_node(self) -> None:
        """The newest node is where the robot is now: tracking continues from its frame."""
        self.track = np.zeros(3)

    def step(
        self, odometry: FloatArray, points: FloatArray, stamp: float | None = None
    ) -> tuple[FloatArray, Registration | None]:
        """Track one scan (taken at ``stamp`` s): its pose relative to the newest node, and the passing match.

        The match is None when tracking is off or failed; the pose is then the
        odometry guess.
        """
        assert self.last_odometry is not None  # the first scan starts the map instead
        self._elapsed = elapsed(stamp, self.last_stamp)
        increment = se2.between(self.last_odometry, odometry)
        guess = se2.compose(self.track, increment)
        reg = self.follow(guess, increment, points)
        self._previous_increment = increment
        pose = guess if reg is None else reg.pose
        if self.config.track_scans and (reg is not None or self._velocity is not None):
            self._velocity = se2.between(self.track, pose)
            self._velocity_dt = self._elapsed
        return pose, reg

    def _coasting_velocity(self) -> FloatArray:
        """The constant-velocity guess's motion for this scan: the last tracked one, or none yet.

        With ``track_velocity_time_scaled`` it is followed for this scan's
        elapsed time rather than for one scan (:mod:`.velocity_time`).
        """
        if self._velocity is None:
            return np.zeros(3)
        if not self.config.track_velocity_time_scaled:
            return self._velocity
        scaled = scaled_velocity(
            self._velocity, self._elapsed, self._velocity_dt, self.config.track_velocity_max_time_ratio
        )
        if not np.array_equal(scaled, self._velocity):  # the key appears only in runs that scaled a guess
            self.counters["tracking_velocity_time_scaled"] = self.counters.get("tracking_velocity_time_scaled", 0) + 1
        return scaled

    def moved_enough(self, relative: FloatArray) -> bool:
        """Whether a pose relative to the newest node is far enough from it to become a node."""
        return math.hypot(relative[0], relative[1]) >= self.config.node_translation_m or abs(
            relative[2]
        ) >= math.radians(self.config.node_rotation_deg)

    def follow(self, guess: FloatArray, increment: FloatArray, points: FloatArray) -> Registration | None:
        """Track a scan against the local map; the passing registration, or None (untracked: the guess stands).

        Chaining scan-to-map matches keeps each guess within one scan period
        of odometry error instead of a whole node step (up to 28.6 deg of raw
        odometry). The odometry can also stall and then catch up (mit-csail
        repeats its odometry on 87 scans and then jumps by up to 0.95 m; the
        tracked motion already holds what it missed), so when the odometry
        guess and the constant-velocity guess (the last tracked motion)
        disagree, both are tried and the better fit wins; with
        ``track_velocity_only_after_stall`` only where this scan's or the
        previous scan's odometry increment is exactly zero
        (:func:`.gating.odometry_stalled`). With ``track_velocity_time_scaled``
        the last motion is followed for this scan's elapsed time rather than
        for one scan (:meth:`_coasting_velocity`).

        How far the guess may be trusted depends on how much odometry it
        holds: a scan period of a few centimetres gets the tight ``track_*``
        prior and gates, an increment as long as a node step (logs that keep
        one scan per 0.5 m, like the SLAM-corrected ones) gets the node-step
        ``odometry_sigma_*`` / ``seq_max_correction_*`` ones, and in between
        they are interpolated (:meth:`track_limits`).
        """
        cfg = self.config
        if not cfg.track_scans:
            return None
        target = self._back.local_map()
        limits = self.track_limits(increment)
        reg, good, _ = self.attempt(target, points, guess, *limits)
        coasting = se2.compose(self.track, self._coasting_velocity())
        gap = se2.between(guess, coasting)
        if (
            cfg.track_velocity_guess
            and self._velocity is not None
            and (not cfg.track_velocity_only_after_stall or odometry_stalled(increment, self._previous_increment))
            and (math.hypot(gap[0], gap[1]) > limits[1] / 2 or abs(gap[2]) > math.radians(limits[2] / 2))
        ):
            alt, alt_good, _ = self.attempt(target, points, coasting, *limits)
            if alt_good and not velocity_match_allowed(alt.pose, guess, good, limits[3]):  # type: ignore[union-attr]
                alt_good = False
                self.counters["tracking_velocity_rejected"] += 1
            if (
                alt_good
                and good
                and alt.fitness > reg.fitness  # type: ignore[union-attr]
                and self._slide_refused(target, points, alt, reg, guess, limits[1])  # type: ignore[arg-type]
            ):
                alt_good = False
            if alt_good and (not good or alt.fitness > reg.fitness):  # type: ignore[union-attr]
                reg, good = alt, True
                self.counters["tracking_velocity_guess"] += 1
        if good:
            correction = se2.between(guess, reg.pose)  # type: ignore[union-attr]
            if reg.fitness < cfg.track_wide_min_fitness and self._corrections.is_outlier(  # type: ignore[union-attr]
                correction, cfg.track_outlier_factor
            ):
                good = False
                self.counters["tracking_outliers_rejected"] += 1
            else:
                self._corrections.add(correction)
        if good:
            self.counters["scans_tracked"] += 1
            return reg
        self.counters["tracking_failures"] += 1
        return None

    def _slide_refused(
        self, target: Target, points: FloatArray, alt: Registration, reg: Registration, guess: FloatArray, max_m: float
    ) -> bool:
        """Whether velocity match ``alt`` may not replace passing odometry match ``reg`` (:mod:`.velocity_slide`)."""
        cfg = self.config
        if not cfg.track_velocity_max_shift and cfg.track_velocity_distinct_ratio <= 0:
            return False
        why = slide_refused(
            target,
            points,
            alt.pose,
            reg.pose,
            guess,
            max_m if cfg.track_velocity_max_shift else None,
            cfg.track_velocity_distinct_ratio,
            cfg.point_sigma_m,
        )
        if why:  # the key appears only in runs that refused a slide: the others keep the counters they had
            self.counters["tracking_velocity_slides_refused"] = (
                self.counters.get("tracking_velocity_slides_refused", 0) + 1
            )
        return bool(why)

    def track_limits(self, increment: FloatArray) -> tuple[IcpParams, float, float, float]:
        """ICP parameters, correction gates (m, deg) and wide rotation gate (deg) for a guess holding ``increment``.

        ``share`` is the increment as a fraction of a node step (distance or
        rotation, whichever is larger, capped at 1): 0 gives the ``track_*``
        values, 1 the node-step values, linear in between. The wide rotation
        gate shrinks to the node-step gate too: on intel-corrected (0.5 m
        between scans, odometry degraded by 0.1 m / 1 deg) a 30 deg gate let
        one wrong turn through on seed 1 (ATE 0.42 m instead of 0.07 m).
        """
        cfg = self.config
        share: float = min(
            1.0,
            max(
                math.hypot(increment[0], increment[1]) / cfg.node_translation_m,
                abs(increment[2]) / math.radians(cfg.node_rotation_deg),
            ),
        )

        def mix(scan: float, step: float) -> float:
            return scan + share * (step - scan)

        params = replace(
            self._track_icp,
            max_correspondence_m=mix(cfg.track_max_correspondence_m, cfg.icp_max_correspondence_m),
            prior_sigma_xy_m=mix(cfg.track_prior_sigma_xy_m, cfg.odometry_sigma_xy_m),
            prior_sigma_theta_rad=math.radians(mix(cfg.track_prior_sigma_theta_deg, cfg.odometry_sigma_theta_deg)),
        )
        max_deg = mix(cfg.track_max_correction_deg, cfg.seq_max_correction_deg)
        return (
            params,
            mix(cfg.track_max_correction_m, cfg.seq_max_correction_m),
            max_deg,
            max(max_deg, mix(cfg.track_wide_correction_deg, cfg.seq_max_correction_deg)),
        )

    def attempt(
        self,
        target: Target,
        points: FloatArray,
        guess: FloatArray,
        params: IcpParams,
        max_m: float,
        max_deg: float,
        wide_deg: float | None = None,
    ) -> tuple[Registration | None, bool, bool]:
        """ICP from ``guess``; if it fails its tests, from the guess rotated by +-k * ``seq_retry_rotation_deg``.

        Odometry heading errors (slipping wheels while turning, a robot
        spinning at 2 rad/s on mit-csail, where the odometry's turn is 20 deg
        off within 0.4 s) are what most often put the guess outside ICP's
        basin, and a rotated start recovers them. A match must stay within
        ``max_m`` / ``max_deg`` of the guess; with ``wide_deg`` a match that
        turns the guess by up to ``wide_deg`` also passes if it fits clearly
        (inlier fraction >= ``track_wide_min_fitness``): only a scan that
        really explains the local map may overrule the odometry's heading by
        that much. Among passing matches the narrow ones win, then the best
        fit. Returns ``(registration, passed, recovered by a retry)``.
        """
        cfg = self.config
        reg = try_register(target, points, guess, params)
        if self.match_ok(reg, guess, max_m, max_deg):
            return reg, True, False
        candidates = [reg]
        step_rad = math.radians(cfg.seq_retry_rotation_deg)
        for k in range(1, cfg.seq_retries + 1):
            for sign in (1.0, -1.0):
                candidates.append(
                    try_register(target, points, guess + np.array([0.0, 0.0, sign * k * step_rad]), params)
                )
        tiers = [(max_deg, cfg.seq_min_fitness)]
        if wide_deg is not None:
            tiers.append((wide_deg, cfg.track_wide_min_fitness))
        for limit_deg, min_fitness in tiers:
            passing = [c for c in candidates if self.match_ok(c, guess, max_m, limit_deg, min_fitness)]
            if passing:
                return max(passing, key=lambda c: c.fitness), True, True  # type: ignore[union-attr]
        return reg, False, False

    def match_ok(
        self,
        reg: Registration | None,
        guess: FloatArray,
        max_m: float,
        max_deg: float,
        min_fitness: float | None = None,
    ) -> bool:
        """Converged, fits (inlier fraction, RMS) and moved ``guess`` by at most ``max_m`` / ``max_deg``."""
        cfg = self.config
        fitness = cfg.seq_min_fitness if min_fitness is None else min_fitness
        if reg is None or not reg.converged or reg.fitness < fitness or reg.rmse_m > cfg.seq_max_rmse_m:
            return False
        corr = se2.between(guess, reg.pose)
        return math.hypot(corr[0], corr[1]) <= max_m and abs(corr[2]) <= math.radians(max_deg)

    def span_edges(self, relative: FloatArray, points: FloatArray) -> list[SpanEdge]:
        """The new node's edge spanning ``span_nodes`` steps (:mod:`.span_edges`), or none (off, too early, or failed).

        ``relative`` is the new node's sequential edge from the newest node;
        the new node is not in the back end yet (its key is the node count).
        """
        cfg = self.config
        key = len(self._back.odometry)
        nodes = span_target_nodes(key, cfg.span_nodes, cfg.span_map_nodes)
        if not nodes:
            return []
        first = nodes[-1]
        guess = span_guess(self._back.estimates, first, self._back.newest, relative)
        reg, good, _ = self.attempt(
            self._back.target(nodes, first),
            points,
            guess,
            self._seq_icp,
            cfg.span_max_correction_m,
            cfg.span_max_correction_deg,
        )
        if not good or reg is None:
            self.counters["span_failures"] = self.counters.get("span_failures", 0) + 1
            return []
        self.counters["span_edges"] = self.counters.get("span_edges", 0) + 1
        covariance = np.asarray(
            np.linalg.inv(reg.information + self._seq_prior) * cfg.span_sigma_scale**2 + self._floor, dtype=np.float64
        )
        if not cfg.span_translation:
            covariance = np.diag([(100.0 * cfg.fallback_sigma_xy_m) ** 2] * 2 + [covariance[2, 2]])
        return [SpanEdge(first, key, reg.pose, covariance, kernel=self.config.span_kernel)]

    def sequential_edge(
        self,
        step: FloatArray,
        points: FloatArray,
        index: int,
        tracked: Registration | None,
        odometry_step: FloatArray | None = None,
    ) -> tuple[FloatArray, FloatArray]:
        """The edge from the newest node to a new one: its scan match, or the guess ``step`` when the match is poor.

        With tracking the match is the tracking registration itself (or
        nothing: tracking failed and ``step`` is odometry since the last
        tracked scan). Without it, the node scan is matched from the odometry
        step, retried from rotated guesses (:meth:`attempt`). With
        ``odometry_trust`` and the node's ``odometry_step`` (the odometry
        increment between the two nodes), a match is fused with that step as
        far as the odometry has earned it (:mod:`.odometry_trust`); with
        ``odometry_trust_factors`` too, the edge stays the match and the
        odometry steps judged at this node are left in :attr:`odometry_factors`.
        """
        cfg = self.config
        self.odometry_factors = []
        self.run_factors = []
        if cfg.track_scans:
            reg, good = tracked, tracked is not None
        else:
            reg, good, recovered = self.attempt(
                self._back.local_map(),
                points,
                step,
                self._seq_icp,
                cfg.seq_max_correction_m,
                cfg.seq_max_correction_deg,
            )
            if recovered:
                self.counters["sequential_retries_recovered"] += 1
        if good and reg is not None:
            self.counters["sequential_matches"] += 1
            self._consecutive_fallbacks = 0
            covariance = (shaped_covariance if cfg.match_covariance_shaped else floor_covariance)(
                reg.information, self._seq_prior, self._floor
            )
            if cfg.odometry_trust and cfg.odometry_trust_factors and odometry_step is not None:
                # the new node's key is the number of nodes so far
                self.odometry_factors = self._odometry_factors.add(
                    len(self._back.odometry), odometry_step, reg.pose, covariance
                )
                self.counters["odometry_fused"] += len(self.odometry_factors)
                if self._odometry_runs is not None:
                    self.run_factors = self._odometry_runs.add(
                        len(self._back.odometry), odometry_step, reg.pose, covariance
                    )
                    self.counters["odometry_run_factors"] = self.counters.get("odometry_run_factors", 0) + len(
                        self.run_factors
                    )
                covariance = self._odometry_factors.match_covariance(len(self._back.odometry), covariance)
            elif cfg.odometry_trust and odometry_step is not None:
                fused = self._odometry_trust.fuse(odometry_step, reg.pose, covariance)
                self._odometry_trust.add(odometry_step, reg.pose)
                if fused is not None:
                    self.counters["odometry_fused"] += 1
                    return fused
            return reg.pose, covariance
        self.counters["odometry_fallbacks"] += 1
        if self._odometry_runs is not None:
            self._odometry_runs.reset()
        self._consecutive_fallbacks += 1
        if self._consecutive_fallbacks >= cfg.max_consecutive_fallbacks:
            detail = (
                "no usable points"
                if reg is None
                else (f"converged={reg.converged}, fitness={reg.fitness:.2f}, rmse={reg.rmse_m:.3f} m")
            )
            raise BaselineError(
                f"gtsam-graph: scan {index}: scan registration failed on {self._consecutive_fallbacks} "
                f"consecutive nodes (last: {detail}); the front-end has lost track (limit max_consecutive_fallbacks="
                f"{cfg.max_consecutive_fallbacks})"
            )
        return step, self._fallback
