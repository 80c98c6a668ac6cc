"""Place recognition of :class:`~albot1.methods.baselines.gtsam_graph.mapper.GtsamGraphMapper`.

Loops whose drift is beyond the loop closer's search (:mod:`.loop_closer`):
a branch-and-bound match of the local map over the whole region the drift
allows (:func:`.correlative.branch_and_bound_search`), refined by ICP and
judged by the loop tests; its confirmed matches go through the loop closer's
book (``place_closures_accepted`` counts them among
``loop_closures_accepted``).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from albot1.geometry import se2
from albot1.geometry.grid import first_per_cell
from albot1.methods.baselines.gtsam_graph.backend import BackEnd
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.correlative import GlobalWindow, branch_and_bound_search
from albot1.methods.baselines.gtsam_graph.loop_closer import LoopCloser, loop_match
from albot1.methods.baselines.gtsam_graph.loop_closure import Confirmer, verify
from albot1.methods.baselines.gtsam_graph.registration import try_register


class PlaceRecognition:
    """Branch-and-bound place recognition over the region the drift allows."""

    def __init__(self, config: GtsamGraphConfig, back: BackEnd, closer: LoopCloser, counters: dict[str, int]) -> None:
        self.config = config
        self.counters = counters
        self._back = back
        self._closer = closer
        self._icp = config.icp(loop=True)
        # A place-recognition pose is already the best of a fine grid: ICP may move it by little more than a cell.
        self._confirmer = Confirmer(
            replace(
                closer.tests,
                max_correction_m=2.0 * config.loop_agreement_m,
                max_correction_rad=2.0 * math.radians(config.loop_agreement_deg),
            )
        )

    def recognise(self, key: int) -> None:
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
        back = self._back
        reject = self._closer.reject
        last = key - cfg.loop_min_node_gap
        if last < 0:
            return
        graph_m = back.graph_distances(key)[: last + 1]
        near_m = np.hypot(*(back.estimates[: last + 1, :2] - back.estimates[key, :2]).T)
        radius_m = np.minimum(cfg.place_max_radius_m, cfg.place_drift_rate * graph_m)
        chosen = np.flatnonzero((graph_m >= cfg.place_min_path_m) & (near_m <= radius_m))
        if not chosen.size:
            return
        self.counters["place_searches"] += 1
        target = back.target((int(n) for n in chosen), key)
        source = back.target(range(max(0, key - cfg.place_source_nodes + 1), key + 1), key).points
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
            reject(f"place-score {found.score:.2f}")
            return
        if found.ambiguity > cfg.place_max_ambiguity:
            reject(f"place-ambiguous ({found.ambiguity:.2f})")
            return
        world = se2.compose(back.estimates[key], found.pose)
        j = int(chosen[np.argmin(np.hypot(*(back.estimates[chosen, :2] - world[:2]).T))])
        nodes = range(max(0, j - cfg.loop_submap_nodes), min(last, j + cfg.loop_submap_nodes) + 1)
        guess = se2.between(back.estimates[j], world)
        submap = back.target(nodes, j)
        reg = try_register(submap, back.scans[key], guess, self._icp)
        if reg is None:
            reject("place-too-few-points")
            return
        covariance, reason = verify(reg, guess, self._confirmer.tests, self._closer.prior)
        if covariance is not None:
            reason = self._closer.distinct(submap.points, key, reg.pose)
            covariance = None if reason else covariance
        if covariance is None:
            reject(f"place-{reason}")
            return
        match = loop_match(back, key, j, reg, covariance)
        accepted, expired = self._confirmer.offer(key, [match], cfg.place_every_nodes)
        if expired:
            reject("place-not-confirmed", expired)
        if accepted:
            self.counters["place_closures_accepted"] += len(accepted)
            self._closer.add(accepted)
