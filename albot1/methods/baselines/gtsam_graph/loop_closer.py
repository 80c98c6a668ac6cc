"""The loop closer of :class:`~albot1.methods.baselines.gtsam_graph.mapper.GtsamGraphMapper`.

At every ``loop_every_nodes``-th node it tries the earlier nodes near the
current estimate (within a radius that grows with the path driven since the
last closure): ICP of the node's scan against each one's submap, seeded from
a correlative search when the estimate may have drifted beyond ICP's basin,
then the acceptance tests and the confirmation of :mod:`.loop_closure`. It
also keeps the book of every closure source (place recognition,
:mod:`.place_recognition`, feeds its matches through :meth:`LoopCloser.add`
and :meth:`LoopCloser.reject`): the loop edges go to the back end, rejections
are counted by reason.
"""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph.backend import BackEnd
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.correlative import SearchWindow, correlative_search
from albot1.methods.baselines.gtsam_graph.loop_closure import (
    Confirmer,
    LoopMatch,
    LoopTests,
    find_candidates,
    search_radius,
    verify,
)
from albot1.methods.baselines.gtsam_graph.loop_distinct import distinct_alignment
from albot1.methods.baselines.gtsam_graph.registration import Registration, try_register


def loop_tests(config: GtsamGraphConfig) -> LoopTests:
    """The acceptance thresholds of a loop match, from the config."""
    return LoopTests(
        min_fitness=config.loop_min_fitness,
        max_rmse_m=config.loop_max_rmse_m,
        max_correction_m=config.loop_max_correction_m,
        max_correction_rad=math.radians(config.loop_max_correction_deg),
        min_sigma_ratio=config.loop_min_sigma_ratio,
        confirmations=config.loop_confirmations,
        agreement_m=config.loop_agreement_m,
        agreement_rad=math.radians(config.loop_agreement_deg),
    )


def loop_prior(config: GtsamGraphConfig) -> FloatArray:
    """The vanishing prior of a loop match's covariance.

    It keeps the covariance invertible while letting directions the scans do
    not constrain show up as huge variances, which is what the degeneracy
    (corridor) test looks for.
    """
    return 1e-6 * np.diag([config.loop_max_correction_m**-2] * 2 + [math.radians(config.loop_max_correction_deg) ** -2])


def loop_match(back: BackEnd, key: int, j: int, reg: Registration, covariance: FloatArray) -> LoopMatch:
    """The match of node ``key`` to node ``j`` with the correction it implies for ``key``'s estimate."""
    implied = se2.compose(back.estimates[j], reg.pose)
    correction = np.array([*(implied[:2] - back.estimates[key, :2]), se2.wrap(implied[2] - back.estimates[key, 2])])
    return LoopMatch(key, j, reg.pose, covariance + back.config.match_floor(), correction)


class LoopCloser:
    """Loop closures near the current estimate, and the book of every closure added or refused."""

    def __init__(self, config: GtsamGraphConfig, back: BackEnd, counters: dict[str, int]) -> None:
        self.config = config
        self.counters = counters
        self._back = back
        self._icp = config.icp(loop=True)
        self.tests = loop_tests(config)
        self.prior = loop_prior(config)
        self._confirmer = Confirmer(self.tests)
        self._path_since_closure = 0.0
        self.rejections: dict[str, int] = {}

    def travelled(self, distance_m: float) -> None:
        """The robot drove ``distance_m`` more since the last closure (the search radius grows with it)."""
        self._path_since_closure += distance_m

    def close_loops(self, key: int) -> None:
        """Match node ``key`` against the earlier nodes near its estimate; add the confirmed matches."""
        cfg = self.config
        back = self._back
        radius = search_radius(
            cfg.loop_search_radius_m, cfg.loop_radius_growth, cfg.loop_max_search_radius_m, self._path_since_closure
        )
        candidates = find_candidates(
            back.estimates[:, :2],
            key,
            radius,
            cfg.loop_min_node_gap,
            cfg.loop_max_candidates,
            separation=2 * cfg.loop_submap_nodes + 1,
        )
        verified: list[LoopMatch] = []
        for j in candidates:
            self.counters["loop_candidates"] += 1
            guess = se2.between(back.estimates[j], back.estimates[key])
            nodes = range(
                max(0, j - cfg.loop_submap_nodes), min(key - cfg.loop_min_node_gap, j + cfg.loop_submap_nodes) + 1
            )
            target = back.target(nodes, j)
            reg = try_register(target, back.scans[key], guess, self._icp)
            if reg is None:
                self.reject("too few points")
                continue
            covariance, reason = verify(reg, guess, self.tests, self.prior)
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
                coarse = correlative_search(target.points, back.scans[key], guess, window)
                self.counters["loop_coarse_searches"] += 1
                retry = try_register(target, back.scans[key], coarse.pose, self._icp)
                if coarse.ambiguity > cfg.loop_max_ambiguity:
                    reason = f"ambiguous ({coarse.ambiguity:.2f})"
                elif retry is not None:
                    cov, why = verify(retry, guess, self.tests, self.prior)
                    if cov is not None:
                        covariance, reason, reg = cov, "", retry
            if covariance is not None:
                reason = self.distinct(target.points, key, reg.pose)
                covariance = None if reason else covariance
            if covariance is None:
                self.reject(reason)
                continue
            verified.append(loop_match(back, key, j, reg, covariance))
        accepted, expired = self._confirmer.offer(key, verified, cfg.loop_every_nodes)
        if expired:
            self.reject("not confirmed", expired)
        if accepted:
            self.add(accepted)

    def distinct(self, target: FloatArray, key: int, pose: FloatArray) -> str:
        """``""`` unless the distinct-alignment check is on and refuses node ``key``'s match at ``pose``: the reason."""
        cfg = self.config
        if cfg.loop_distinct_half_width_m <= 0:
            return ""
        window = SearchWindow(
            half_width_m=cfg.loop_distinct_half_width_m,
            step_m=cfg.loop_coarse_step_m,
            half_angle_rad=math.radians(cfg.loop_coarse_half_angle_deg),
            step_rad=math.radians(cfg.loop_coarse_step_deg),
        )
        return distinct_alignment(target, self._back.scans[key], pose, window, cfg.loop_distinct_max_ambiguity)

    def add(self, accepted: list[LoopMatch]) -> None:
        """Confirmed loop matches become robust edges of the graph; the path since the last closure starts over."""
        self._back.add_loops(accepted)
        self.counters["loop_closures_accepted"] += len(accepted)
        self._path_since_closure = 0.0

    def reject(self, reason: str, count: int = 1) -> None:
        """Count ``count`` refused matches under the first word of ``reason``."""
        self.counters["loop_closures_rejected"] += count
        kind = reason.split(" ")[0]
        self.rejections[kind] = self.rejections.get(kind, 0) + count

    def flush(self) -> None:
        """At the end of the run: matches still waiting for confirmation are refused."""
        unconfirmed = self._confirmer.flush()
        if unconfirmed:
            self.reject("not confirmed", unconfirmed)
