"""Loop-closure front-end: which earlier nodes to try, and which matches to believe.

A wrong loop closure is far more harmful than a missed one (it folds the
map), so a match becomes an edge only after every test below passes:

1. registration converged with a high inlier fraction (``fitness``) and a
   small inlier RMS distance;
2. it is *consistent with the current estimate*: the correction it implies
   is within the drift the estimate can plausibly have;
3. it is *well conditioned*: the translation is constrained in both
   directions (a corridor matches anywhere along itself);
4. it is *confirmed*: ``confirmations`` consecutive searching nodes produced
   matches implying the same correction (a single lucky alignment of
   similar-looking rooms rarely repeats at the next node).

The edges that pass still carry a robust kernel in the back-end (Grisetti et
al. 2010; Sunderhauf & Protzel 2012 on why that matters).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph.registration import Registration


@dataclass(frozen=True)
class LoopTests:
    """Acceptance thresholds of a loop match (from the config)."""

    min_fitness: float
    max_rmse_m: float
    max_correction_m: float
    max_correction_rad: float
    min_sigma_ratio: float
    confirmations: int
    agreement_m: float
    agreement_rad: float


@dataclass(frozen=True)
class LoopMatch:
    """A verified match of node ``current`` against the submap of node ``candidate``.

    ``relative`` is the pose of ``current`` in ``candidate``'s frame,
    ``covariance`` its additive (x, y, theta) covariance, ``correction`` the
    world-frame shift ``(dx, dy, dtheta)`` it implies for the current node.
    """

    current: int
    candidate: int
    relative: FloatArray
    covariance: FloatArray
    correction: FloatArray


def search_radius(base_m: float, growth: float, cap_m: float, path_since_closure_m: float) -> float:
    """The candidate gate: drift grows with the path driven since the last closure, so does the gate."""
    return min(cap_m, base_m + growth * path_since_closure_m)


def find_candidates(
    positions: FloatArray, current: int, radius_m: float, min_gap: int, max_candidates: int, separation: int
) -> list[int]:
    """Earlier nodes near node ``current``: nearest first, at least ``separation`` node indices apart.

    ``positions`` holds the current estimates (x, y) of nodes ``0..current``.
    Nodes within ``min_gap`` of ``current`` are sequential neighbours, not loops.
    """
    last = current - min_gap
    if last < 0:
        return []
    d = np.hypot(*(positions[: last + 1] - positions[current]).T)
    near = np.flatnonzero(d <= radius_m)
    chosen: list[int] = []
    for j in near[np.argsort(d[near], kind="stable")]:
        if all(abs(int(j) - c) >= separation for c in chosen):
            chosen.append(int(j))
            if len(chosen) == max_candidates:
                break
    return chosen


def verify(
    reg: Registration, guess: FloatArray, tests: LoopTests, prior_information: FloatArray
) -> tuple[FloatArray | None, str]:
    """Apply tests 1-3 to a registration; returns ``(covariance, "")`` or ``(None, reason)``."""
    if not reg.converged:
        return None, "not converged"
    if reg.fitness < tests.min_fitness:
        return None, f"fitness {reg.fitness:.2f} < {tests.min_fitness:.2f}"
    if reg.rmse_m > tests.max_rmse_m:
        return None, f"rmse {reg.rmse_m:.3f} m > {tests.max_rmse_m:.3f} m"
    corr = se2.between(guess, reg.pose)
    if math.hypot(corr[0], corr[1]) > tests.max_correction_m or abs(corr[2]) > tests.max_correction_rad:
        return None, "inconsistent with the current estimate"
    try:
        cov = np.asarray(np.linalg.inv(reg.information + prior_information), dtype=np.float64)
    except np.linalg.LinAlgError:
        return None, "singular information"
    eig = np.linalg.eigvalsh(0.5 * (cov[:2, :2] + cov[:2, :2].T))
    if eig[0] <= 0 or math.sqrt(eig[0] / eig[1]) < tests.min_sigma_ratio:
        return None, "degenerate (corridor-like) match"
    return cov, ""


@dataclass
class Confirmer:
    """Holds verified matches until ``confirmations`` consecutive searching nodes agree (test 4)."""

    tests: LoopTests
    pending: list[LoopMatch] = field(default_factory=list)
    added: set[tuple[int, int]] = field(default_factory=set)

    def offer(self, node: int, matches: list[LoopMatch], window: int) -> tuple[list[LoopMatch], int]:
        """Matches of ``node``; returns (matches to add now, pending matches that expired unconfirmed)."""
        recent = [m for m in self.pending if node - m.current <= 2 * window * (self.tests.confirmations - 1)]
        expired = sum(1 for m in self.pending if m not in recent and (m.current, m.candidate) not in self.added)
        accepted: list[LoopMatch] = []
        for match in matches:
            agreeing = [m for m in recent if m.current != node and self._agree(m, match)]
            nodes = {m.current for m in agreeing} | {node}
            if len(nodes) >= self.tests.confirmations:
                for m in [*agreeing, match]:
                    key = (m.current, m.candidate)
                    if key not in self.added:
                        self.added.add(key)
                        accepted.append(m)
        self.pending = [*recent, *matches]
        return accepted, expired

    def flush(self) -> int:
        """Pending matches never confirmed (counted as rejected at the end)."""
        left = sum(1 for m in self.pending if (m.current, m.candidate) not in self.added)
        self.pending = []
        return left

    def _agree(self, a: LoopMatch, b: LoopMatch) -> bool:
        d = a.correction - b.correction
        return bool(math.hypot(d[0], d[1]) < self.tests.agreement_m and abs(se2.wrap(d[2])) < self.tests.agreement_rad)
