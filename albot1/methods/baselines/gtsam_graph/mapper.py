"""``GtsamGraphMapper``: graph-based SLAM behind the mapper protocol.

The method of Grisetti et al. (2010), the thesis's section 2.2.3:

* a **node** whenever odometry says the robot moved 0.5 m or turned 0.5 rad
  since the last node; its scan is stored in the node's frame;
* a **sequential edge** from point-to-line ICP of the node's scan against a
  local map (the last ``local_map_nodes`` node scans), the odometry
  increment being the initial guess and a weak prior; when the match is poor
  (not converged, low inlier fraction, large residual or an implausible
  correction) the edge is the odometry increment with a larger covariance;
* **loop-closure edges** from ICP against the submaps of earlier nodes near
  the current estimate (:mod:`.loop_closure`), added only after strict tests
  and with a robust kernel;
* **place recognition** for loops whose drift is beyond that search: a
  branch-and-bound match of the local map over the region the drift allows
  (:meth:`GtsamGraphMapper._recognise_place`), verified the same way
  (``place_closures_accepted`` counts these among ``loop_closures_accepted``);
* GTSAM **ISAM2** after every node, a final batch **Levenberg-Marquardt** in
  :meth:`GtsamGraphMapper.finish`.

The pose of a scan is the optimised pose of the node it belongs to composed
with the odometry from that node to the scan; the map is every scan
projected with those poses, thinned on a grid.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import replace
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel

from albot1.config.presets import TomlPresets
from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame, Scan
from albot1.geometry import se2
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.correlative import (
    GlobalWindow,
    SearchWindow,
    branch_and_bound_search,
    correlative_search,
)
from albot1.methods.baselines.gtsam_graph.errors import GraphError, RegistrationError
from albot1.methods.baselines.gtsam_graph.graph import PoseGraph
from albot1.methods.baselines.gtsam_graph.loop_closure import (
    Confirmer,
    LoopMatch,
    LoopTests,
    find_candidates,
    search_radius,
    verify,
)
from albot1.methods.baselines.gtsam_graph.refine import RefineTests, accept, seed_poses
from albot1.methods.baselines.gtsam_graph.registration import IcpParams, Registration, Target, line_normals, register
from albot1.methods.baselines.point_map import first_per_cell

FloatArray = NDArray[np.float64]


class GtsamGraphMapper:
    """Pose-graph SLAM with scan-matching edges, verified loop closures, ISAM2 and a final LM."""

    name: ClassVar[str] = "gtsam-graph"
    config_model: ClassVar[type[BaseModel]] = GtsamGraphConfig
    presets = TomlPresets()

    def __init__(self, config: GtsamGraphConfig, *, seed: int = 0) -> None:
        # Nothing here is random; the seed is kept for the protocol and the record.
        self.config = config
        self.seed = seed
        self._graph = PoseGraph(config.isam_relinearize_threshold)
        self._seq_icp = config.icp(loop=False)
        self._loop_icp = config.icp(loop=True)
        self._seq_prior = np.diag(
            [config.odometry_sigma_xy_m**-2] * 2 + [math.radians(config.odometry_sigma_theta_deg) ** -2]
        )
        # A vanishing prior keeps a loop match's covariance invertible while letting directions the scans do not
        # constrain show up as huge variances, which is what the degeneracy (corridor) test looks for.
        self._loop_prior = 1e-6 * np.diag(
            [config.loop_max_correction_m**-2] * 2 + [math.radians(config.loop_max_correction_deg) ** -2]
        )
        self._floor = np.diag(
            [config.match_sigma_floor_xy_m**2] * 2 + [math.radians(config.match_sigma_floor_theta_deg) ** 2]
        )
        self._fallback = np.diag(
            [config.fallback_sigma_xy_m**2] * 2 + [math.radians(config.fallback_sigma_theta_deg) ** 2]
        )
        self._tests = LoopTests(
            min_fitness=config.loop_min_fitness,
            max_rmse_m=config.loop_max_rmse_m,
            max_correction_m=config.loop_max_correction_m,
            max_correction_rad=math.radians(config.loop_max_correction_deg),
            min_sigma_ratio=config.loop_min_sigma_ratio,
            confirmations=config.loop_confirmations,
            agreement_m=config.loop_agreement_m,
            agreement_rad=math.radians(config.loop_agreement_deg),
        )
        self._confirmer = Confirmer(self._tests)
        # A place-recognition pose is already the best of a fine grid: ICP may move it by little more than a cell.
        self._place_confirmer = Confirmer(
            replace(
                self._tests,
                max_correction_m=2.0 * config.loop_agreement_m,
                max_correction_rad=2.0 * math.radians(config.loop_agreement_deg),
            )
        )
        self._refine_icp = config.refine_icp()
        self._track_icp = config.track_icp()
        self._refine_tests = RefineTests(
            min_fitness=config.refine_min_fitness,
            max_rmse_m=config.refine_max_rmse_m,
            max_correction_m=config.refine_max_correction_m,
            max_correction_rad=math.radians(config.refine_max_correction_deg),
        )
        # Tracking: the latest scan's pose in the frame of the newest node, and the local map it is matched against.
        self._track = np.zeros(3)
        self._velocity = np.zeros(3)  # the last tracked scan-to-scan motion
        self._last_odometry: FloatArray | None = None
        self._local: Target | None = None
        # Per node.
        self._node_odometry: list[FloatArray] = []
        self._node_steps: list[FloatArray] = []  # measured pose of node k in node k-1's frame (node 0: zeros)
        self._node_scans: list[FloatArray] = []
        self._node_lines: list[tuple[FloatArray, FloatArray]] = []  # line-like points and normals, node frame
        self._node_frame: list[int] = []
        self._estimates = np.empty((0, 3))
        # Per scan.
        self._scan_node: list[int] = []
        self._scan_offset: list[FloatArray] = []
        self._scan_points: list[FloatArray] = []
        # Bookkeeping.
        self._path_since_closure = 0.0
        self._consecutive_fallbacks = 0
        self._loop_edges: list[tuple[int, int]] = []
        self._rejections: dict[str, int] = {}
        self.counters: dict[str, int] = {
            "views": 0,
            "nodes": 0,
            "sequential_matches": 0,
            "sequential_retries_recovered": 0,
            "scans_tracked": 0,
            "tracking_failures": 0,
            "tracking_velocity_guess": 0,
            "odometry_fallbacks": 0,
            "loop_candidates": 0,
            "loop_coarse_searches": 0,
            "loop_closures_accepted": 0,
            "loop_closures_rejected": 0,
            "place_searches": 0,
            "place_closures_accepted": 0,
            "scans_refined": 0,
        }

    # ------------------------------------------------------------------ input
    def process(self, frame: Frame) -> None:
        """Add the frame's scan to its node, creating a node when the robot moved enough."""
        odometry = np.asarray(frame.odometry, dtype=float)
        if odometry.shape != (3,) or not np.isfinite(odometry).all():
            raise BaselineError(
                f"gtsam-graph: scan {frame.index}: expected a finite odometry pose (x, y, theta), "
                f"got {odometry.tolist()}"
            )
        points = self._preprocess(frame.scan, frame.index)
        self.counters["views"] += 1
        try:
            if self._last_odometry is None:
                self._start(odometry, points, frame.index)
            else:
                increment = se2.between(self._last_odometry, odometry)
                guess = se2.compose(self._track, increment)
                reg = self._follow(guess, increment, points)
                pose = guess if reg is None else reg.pose
                if self.config.track_scans:
                    self._velocity = se2.between(self._track, pose)
                if self._moved_enough(pose):
                    self._add_node(odometry, pose, points, frame.index, reg)
                else:
                    self._track = pose
        except (
            GraphError,
            RegistrationError,
        ) as exc:  # re-raised as the method's error so the runner names the dataset
            raise BaselineError(f"gtsam-graph: scan {frame.index}: {exc}") from exc
        self._last_odometry = odometry
        self._scan_node.append(len(self._node_odometry) - 1)
        self._scan_offset.append(self._track.copy())
        self._scan_points.append(points)

    def _moved_enough(self, relative: FloatArray) -> bool:
        """Whether a pose relative to the newest node is far enough from it to become a node."""
        return math.hypot(relative[0], relative[1]) >= self.config.node_translation_m or abs(
            relative[2]
        ) >= math.radians(self.config.node_rotation_deg)

    def _local_map(self) -> Target:
        """The last ``local_map_nodes`` node scans in the newest node's frame (built once per node)."""
        if self._local is None:
            last = len(self._node_odometry) - 1
            self._local = self._target(range(max(0, last - self.config.local_map_nodes + 1), last + 1), last)
        return self._local

    def _follow(self, guess: FloatArray, increment: FloatArray, points: FloatArray) -> Registration | None:
        """Track a scan against the local map; the passing registration, or None (untracked: the guess stands).

        Chaining scan-to-map matches keeps each guess within one scan period
        of odometry error instead of a whole node step (up to 28.6 deg of raw
        odometry). The odometry can also stall and then catch up (mit-csail
        repeats its odometry on 87 scans and then jumps by up to 0.95 m; the
        tracked motion already holds what it missed), so when the odometry
        guess and the constant-velocity guess (the last tracked motion)
        disagree, both are tried and the better fit wins.

        How far the guess may be trusted depends on how much odometry it
        holds: a scan period of a few centimetres gets the tight ``track_*``
        prior and gates, an increment as long as a node step (logs that keep
        one scan per 0.5 m, like the SLAM-corrected ones) gets the node-step
        ``odometry_sigma_*`` / ``seq_max_correction_*`` ones, and in between
        they are interpolated (:meth:`_track_limits`).
        """
        cfg = self.config
        if not cfg.track_scans:
            return None
        target = self._local_map()
        limits = self._track_limits(increment)
        reg, good, _ = self._attempt(target, points, guess, *limits)
        coasting = se2.compose(self._track, self._velocity)
        gap = se2.between(guess, coasting)
        if cfg.track_velocity_guess and (
            math.hypot(gap[0], gap[1]) > limits[1] / 2 or abs(gap[2]) > math.radians(limits[2] / 2)
        ):
            alt, alt_good, _ = self._attempt(target, points, coasting, *limits)
            if alt_good and (not good or alt.fitness > reg.fitness):  # type: ignore[union-attr]
                reg, good = alt, True
                self.counters["tracking_velocity_guess"] += 1
        if good:
            self.counters["scans_tracked"] += 1
            return reg
        self.counters["tracking_failures"] += 1
        return None

    def _track_limits(self, increment: FloatArray) -> tuple[IcpParams, float, float, float]:
        """ICP parameters, correction gates (m, deg) and wide rotation gate (deg) for a guess holding ``increment``.

        ``share`` is the increment as a fraction of a node step (distance or
        rotation, whichever is larger, capped at 1): 0 gives the ``track_*``
        values, 1 the node-step values, linear in between. The wide rotation
        gate shrinks to the node-step gate too: on intel-corrected (0.5 m
        between scans, odometry degraded by 0.1 m / 1 deg) a 30 deg gate let
        one wrong turn through on seed 1 (ATE 0.42 m instead of 0.07 m).
        """
        cfg = self.config
        share = min(
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

    def _attempt(
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
        reg = self._register(target, points, guess, params)
        if self._match_ok(reg, guess, max_m, max_deg):
            return reg, True, False
        candidates = [reg]
        step_rad = math.radians(cfg.seq_retry_rotation_deg)
        for k in range(1, cfg.seq_retries + 1):
            for sign in (1.0, -1.0):
                candidates.append(
                    self._register(target, points, guess + np.array([0.0, 0.0, sign * k * step_rad]), params)
                )
        tiers = [(max_deg, cfg.seq_min_fitness)]
        if wide_deg is not None:
            tiers.append((wide_deg, cfg.track_wide_min_fitness))
        for limit_deg, min_fitness in tiers:
            passing = [c for c in candidates if self._match_ok(c, guess, max_m, limit_deg, min_fitness)]
            if passing:
                return max(passing, key=lambda c: c.fitness), True, True  # type: ignore[union-attr]
        return reg, False, False

    def _preprocess(self, scan: Scan, index: int) -> FloatArray:
        """Valid beams within the range limits, as points, thinned to one per ``scan_voxel_m`` cell."""
        ranges = np.asarray(scan.ranges, dtype=float)
        if np.isinf(ranges).any():
            raise BaselineError(f"gtsam-graph: scan {index}: ranges must be finite or NaN (no return), found inf")
        if not np.isfinite(np.asarray(scan.angles, dtype=float)).all():
            raise BaselineError(f"gtsam-graph: scan {index}: beam angles must be finite")
        pts = scan.points(self.config.min_range_m, self.config.max_range_m)
        cell = self.config.scan_voxel_m
        if cell > 0 and len(pts):
            pts = first_per_cell(pts, cell)
        return pts

    # ------------------------------------------------------------------ nodes and edges
    def _start(self, odometry: FloatArray, points: FloatArray, index: int) -> None:
        self._graph.add_node(np.zeros(3))
        self._graph.update()
        self._remember_node(odometry, np.zeros(3), points, index)
        self._estimates = np.zeros((1, 3))

    def _remember_node(self, odometry: FloatArray, step: FloatArray, points: FloatArray, index: int) -> None:
        """Keep what later scan matching needs of a new node: its odometry, measured step, scan, lines, frame."""
        self._node_odometry.append(odometry)
        self._node_steps.append(np.asarray(step, dtype=float))
        self._track = np.zeros(3)
        self._local = None
        self._node_scans.append(points)
        self._node_lines.append(
            line_normals(points, self.config.normal_neighbours, self.config.normal_radius_m, self.config.max_planarity)
        )
        self._node_frame.append(index)

    def _add_node(
        self, odometry: FloatArray, step: FloatArray, points: FloatArray, index: int, tracked: Registration | None
    ) -> None:
        prev = len(self._node_odometry) - 1
        key = self._graph.add_node(se2.compose(self._estimates[prev], step))
        relative, covariance = self._sequential_edge(prev, step, points, index, tracked)
        self._graph.add_edge(prev, key, relative, covariance)
        self._graph.update()
        self._remember_node(odometry, relative, points, index)
        self._estimates = np.vstack([self._estimates, se2.compose(self._estimates[prev], relative)])
        self._refresh_estimates(range(max(0, key - self.config.local_map_nodes), key + 1))
        self._path_since_closure += math.hypot(relative[0], relative[1])
        if key % self.config.loop_every_nodes == 0:
            self._close_loops(key, index)
        if self.config.place_recognition and key % self.config.place_every_nodes == 0:
            self._recognise_place(key)

    def _sequential_edge(
        self, prev: int, step: FloatArray, points: FloatArray, index: int, tracked: Registration | None
    ) -> tuple[FloatArray, FloatArray]:
        """The edge from node ``prev`` to the new node: its scan match, or the guess ``step`` when the match is poor.

        With tracking the match is the tracking registration itself (or
        nothing: tracking failed and ``step`` is odometry since the last
        tracked scan). Without it, the node scan is matched from the odometry
        step, retried from rotated guesses (:meth:`_attempt`).
        """
        cfg = self.config
        if cfg.track_scans:
            reg, good = tracked, tracked is not None
        else:
            reg, good, recovered = self._attempt(
                self._local_map(), points, step, self._seq_icp, cfg.seq_max_correction_m, cfg.seq_max_correction_deg
            )
            if recovered:
                self.counters["sequential_retries_recovered"] += 1
        if good and reg is not None:
            self.counters["sequential_matches"] += 1
            self._consecutive_fallbacks = 0
            covariance = np.linalg.inv(reg.information + self._seq_prior) + self._floor
            return reg.pose, np.asarray(covariance, dtype=np.float64)
        self.counters["odometry_fallbacks"] += 1
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

    def _match_ok(
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

    def _target(self, nodes: Iterable[int], frame_node: int, poses: FloatArray | None = None) -> Target:
        """The line-like points of ``nodes``' scans, expressed in ``frame_node``'s frame.

        Nodes are placed with ``poses`` (default: the current estimates).
        """
        at = self._estimates if poses is None else poses
        origin = at[frame_node]
        pts, nrm = [], []
        for n in nodes:
            rel = se2.between(origin, at[n])
            c, s = math.cos(rel[2]), math.sin(rel[2])
            pts.append(se2.transform_points(rel, self._node_lines[n][0]))
            nrm.append(self._node_lines[n][1] @ np.array([[c, s], [-s, c]]))
        return Target(np.concatenate(pts), np.concatenate(nrm))

    @staticmethod
    def _register(target: Target, points: FloatArray, guess: FloatArray, params: IcpParams) -> Registration | None:
        """ICP, or None when either side has too few usable points to try."""
        if len(points) < params.min_points or len(target) < params.min_points:
            return None
        return register(target, points, guess, params)

    def _close_loops(self, key: int, index: int) -> None:
        cfg = self.config
        radius = search_radius(
            cfg.loop_search_radius_m, cfg.loop_radius_growth, cfg.loop_max_search_radius_m, self._path_since_closure
        )
        candidates = find_candidates(
            self._estimates[:, :2],
            key,
            radius,
            cfg.loop_min_node_gap,
            cfg.loop_max_candidates,
            separation=2 * cfg.loop_submap_nodes + 1,
        )
        verified: list[LoopMatch] = []
        for j in candidates:
            self.counters["loop_candidates"] += 1
            guess = se2.between(self._estimates[j], self._estimates[key])
            nodes = range(
                max(0, j - cfg.loop_submap_nodes), min(key - cfg.loop_min_node_gap, j + cfg.loop_submap_nodes) + 1
            )
            target = self._target(nodes, j)
            reg = self._register(target, self._node_scans[key], guess, self._loop_icp)
            if reg is None:
                self._reject("too few points")
                continue
            covariance, reason = verify(reg, guess, self._tests, self._loop_prior)
            if covariance is None and cfg.loop_coarse_max_half_width_m > 0:
                # The estimate may have drifted beyond ICP's basin: seed ICP from a correlative search.
                half = min(
                    cfg.loop_coarse_max_half_width_m,
                    max(cfg.loop_coarse_min_half_width_m, cfg.loop_radius_growth * self._path_since_closure),
                )
                window = SearchWindow(
                    half_width_m=half,
                    step_m=cfg.loop_coarse_step_m,
                    half_angle_rad=math.radians(cfg.loop_coarse_half_angle_deg),
                    step_rad=math.radians(cfg.loop_coarse_step_deg),
                )
                coarse = correlative_search(target.points, self._node_scans[key], guess, window)
                self.counters["loop_coarse_searches"] += 1
                retry = self._register(target, self._node_scans[key], coarse.pose, self._loop_icp)
                if coarse.ambiguity > cfg.loop_max_ambiguity:
                    reason = f"ambiguous ({coarse.ambiguity:.2f})"
                elif retry is not None:
                    cov, why = verify(retry, guess, self._tests, self._loop_prior)
                    if cov is not None:
                        covariance, reason, reg = cov, "", retry
            if covariance is None:
                self._reject(reason)
                continue
            implied = se2.compose(self._estimates[j], reg.pose)
            correction = np.array(
                [*(implied[:2] - self._estimates[key, :2]), se2.wrap(implied[2] - self._estimates[key, 2])]
            )
            verified.append(LoopMatch(key, j, reg.pose, covariance + self._floor, correction))
        accepted, expired = self._confirmer.offer(key, verified, cfg.loop_every_nodes)
        if expired:
            self._reject("not confirmed", expired)
        if accepted:
            self._add_loops(accepted)

    def _add_loops(self, accepted: list[LoopMatch]) -> None:
        """Add confirmed loop matches as robust edges and bring the estimates up to date."""
        cfg = self.config
        for match in accepted:
            self._graph.add_edge(
                match.candidate,
                match.current,
                match.relative,
                match.covariance,
                kernel=cfg.loop_kernel,
                kernel_scale=cfg.loop_kernel_scale,
            )
            self._loop_edges.append((match.candidate, match.current))
        self.counters["loop_closures_accepted"] += len(accepted)
        self._graph.update(cfg.isam_extra_updates_on_loop)
        self._estimates = self._graph.estimates()
        self._local = None
        self._path_since_closure = 0.0

    def _recognise_place(self, key: int) -> None:
        """Loops beyond the ordinary gate: a branch-and-bound match over the whole region the drift allows.

        Drift grows with the path driven between two visits, and a loop
        closure shortens that path, so an earlier node ``j`` is searched when
        it lies within ``place_drift_rate`` x its graph distance from node
        ``key`` (the shortest path through the sequential and loop edges: a
        proxy for their relative uncertainty that needs no marginals). The
        local map of the last ``place_source_nodes`` node scans (one sparse
        scan holds too little structure) is matched against every such node's
        scan at once, over that whole radius and +-``place_half_angle_deg``
        (:func:`branch_and_bound_search`). The best pose must explain enough
        of the local map and have no distinct rival; ICP of the node's scan
        against the nearest earlier node's submap then refines it, the loop
        tests judge it, and a second search must agree before it is added.
        """
        cfg = self.config
        last = key - cfg.loop_min_node_gap
        if last < 0:
            return
        graph_m = self._graph_distances(key)[: last + 1]
        near_m = np.hypot(*(self._estimates[: last + 1, :2] - self._estimates[key, :2]).T)
        radius_m = np.minimum(cfg.place_max_radius_m, cfg.place_drift_rate * graph_m)
        chosen = np.flatnonzero((graph_m >= cfg.place_min_path_m) & (near_m <= radius_m))
        if not chosen.size:
            return
        self.counters["place_searches"] += 1
        target = self._target((int(n) for n in chosen), key)
        source = self._target(range(max(0, key - cfg.place_source_nodes + 1), key + 1), key).points
        window = GlobalWindow(
            half_width_m=float(radius_m[chosen].max()),
            half_angle_rad=math.radians(cfg.place_half_angle_deg),
            step_rad=math.radians(cfg.place_step_deg),
            cell_m=cfg.place_cell_m,
            sigma_m=cfg.place_sigma_m,
            max_points=cfg.place_max_points,
            max_nodes=cfg.place_max_blocks,
            min_ambiguity=cfg.place_max_ambiguity,
        )
        found = branch_and_bound_search(target.points, first_per_cell(source, cfg.place_cell_m), np.zeros(3), window)
        if found.score < cfg.place_min_score:
            self._reject(f"place-score {found.score:.2f}")
            return
        if found.ambiguity > cfg.place_max_ambiguity:
            self._reject(f"place-ambiguous ({found.ambiguity:.2f})")
            return
        world = se2.compose(self._estimates[key], found.pose)
        j = int(chosen[np.argmin(np.hypot(*(self._estimates[chosen, :2] - world[:2]).T))])
        nodes = range(max(0, j - cfg.loop_submap_nodes), min(last, j + cfg.loop_submap_nodes) + 1)
        guess = se2.between(self._estimates[j], world)
        reg = self._register(self._target(nodes, j), self._node_scans[key], guess, self._loop_icp)
        if reg is None:
            self._reject("place-too-few-points")
            return
        covariance, reason = verify(reg, guess, self._place_confirmer.tests, self._loop_prior)
        if covariance is None:
            self._reject(f"place-{reason}")
            return
        implied = se2.compose(self._estimates[j], reg.pose)
        correction = np.array(
            [*(implied[:2] - self._estimates[key, :2]), se2.wrap(implied[2] - self._estimates[key, 2])]
        )
        match = LoopMatch(key, j, reg.pose, covariance + self._floor, correction)
        accepted, expired = self._place_confirmer.offer(key, [match], cfg.place_every_nodes)
        if expired:
            self._reject("place-not-confirmed", expired)
        if accepted:
            self.counters["place_closures_accepted"] += len(accepted)
            self._add_loops(accepted)

    def _graph_distances(self, key: int) -> FloatArray:
        """Shortest path length (m) from node ``key`` to every node ``0..key`` along sequential and loop edges."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import dijkstra

        n = key + 1
        steps = np.asarray(self._node_steps[1:n], dtype=float).reshape(-1, 3)
        rows = [*range(n - 1), *(a for a, _ in self._loop_edges)]
        cols = [*range(1, n), *(b for _, b in self._loop_edges)]
        lengths = [
            *np.hypot(steps[:, 0], steps[:, 1]),
            *(math.hypot(*(self._estimates[a, :2] - self._estimates[b, :2])) for a, b in self._loop_edges),
        ]
        # csgraph treats a zero weight as a missing edge; a node step can be a pure rotation.
        graph = coo_matrix((np.maximum(lengths, 1e-6), (rows, cols)), shape=(n, n)).tocsr()
        return np.asarray(dijkstra(graph, directed=False, indices=key), dtype=np.float64)

    def _reject(self, reason: str, count: int = 1) -> None:
        self.counters["loop_closures_rejected"] += count
        kind = reason.split(" ")[0]
        self._rejections[kind] = self._rejections.get(kind, 0) + count

    def _refresh_estimates(self, keys: range) -> None:
        for k in keys:
            self._estimates[k] = self._graph.estimate(k)

    # ------------------------------------------------------------------ output
    def finish(self) -> MapperOutput:
        """Final LM, per-scan poses (node pose composed with odometry since the node) and the map."""
        if not self._scan_node:
            return MapperOutput(
                poses=np.empty((0, 3)),
                map=MapData(points=np.empty((0, 2))),
                counters={**self.counters, "updates": 0, "optimisations": 0, "map_points": 0},
            )
        unconfirmed = self._confirmer.flush()
        if unconfirmed:
            self._reject("not confirmed", unconfirmed)
        try:
            nodes = (
                self._graph.optimise(self.config.lm_max_iterations) if self.config.final_lm else self._graph.estimates()
            )
        except GraphError as exc:
            raise BaselineError(f"gtsam-graph: final optimisation: {exc}") from exc
        if not np.isfinite(nodes).all():
            raise BaselineError(
                f"gtsam-graph: the optimised graph of {len(nodes)} nodes has non-finite poses (diverged)"
            )
        poses = self._scan_poses(nodes)
        points = self._project_map(poses)
        n_nodes = len(self._node_odometry)
        counters: dict[str, int | float] = {
            **self.counters,
            "nodes": n_nodes,
            "updates": n_nodes,
            "optimisations": self._graph.optimisations,
            "map_points": int(len(points)),
        }
        extras = {
            "node_scans": [int(i) for i in self._node_frame],
            "loop_edges": [[int(a), int(b)] for a, b in self._loop_edges],
            "loop_rejections": dict(sorted(self._rejections.items())),
        }
        return MapperOutput(poses=poses, map=MapData(points=points), counters=counters, extras=extras)

    def _scan_poses(self, nodes: FloatArray) -> FloatArray:
        """Every scan's pose: node scans take their node's, the others are seeded and refined (:mod:`.refine`)."""
        scan_node = np.asarray(self._scan_node, dtype=np.int64)
        offsets = np.asarray(self._scan_offset, dtype=float)
        poses = seed_poses(nodes, np.asarray(self._node_steps), scan_node, offsets)
        is_node = np.zeros(len(scan_node), dtype=bool)
        is_node[np.asarray(self._node_frame, dtype=np.int64)] = True
        poses[is_node] = nodes[scan_node[is_node]]
        if not self.config.refine_scans:
            return poses
        width = self.config.refine_nodes_either_side
        target: Target | None = None
        target_node = -1
        for i in np.flatnonzero(~is_node):
            k = int(scan_node[i])
            if k != target_node:
                around = range(max(0, k - width), min(len(nodes), k + width + 2))
                target, target_node = self._target(around, k, nodes), k
            assert target is not None
            seed = se2.between(nodes[k], poses[i])
            reg = self._register(target, self._scan_points[i], seed, self._refine_icp)
            if reg is not None and accept(self._refine_tests, seed, reg.pose, reg.converged, reg.fitness, reg.rmse_m):
                poses[i] = se2.compose(nodes[k], reg.pose)
                self.counters["scans_refined"] += 1
        return poses

    def _project_map(self, poses: FloatArray) -> FloatArray:
        """Every ``map_every``-th scan projected with its pose; the first point in each grid cell wins."""
        every = self.config.map_every
        parts = [
            se2.transform_points(poses[i], pts)
            for i, pts in enumerate(self._scan_points)
            if i % every == 0 and len(pts)
        ]
        if not parts:
            return np.empty((0, 2))
        return first_per_cell(np.concatenate(parts), self.config.map_voxel_m)
