"""When a node's match and its odometry disagree beyond their uncertainties, keep the one that earned the smaller.

Off in the default preset (``odometry_trust_earned_level = 0``; measured in
docs/baselines.md, gtsam-graph, "the earned choice"). It refines how
:class:`.odometry_trust.OdometryFactors` judges one matched node step.

Today's judgement weighs the odometry's heading by the variance it has
earned (the spread of its disagreement with recent matches beyond what the
matches claim), but never above its match's (the weight floor,
``odometry_trust_min_variance_ratio``: fr-clinic's wheel odometry slips in
turns). So where a match is off by 1-3 deg while the odometry is perfect
(edmonton-corrected: node 63 turns 28.6 deg, its match claims 1.5 deg and
is 3.2 deg off), the graph keeps the mean of the two and half of the
match's error stays in the map.

The rule here acts only on a step whose odometry step and match disagree
beyond their own stated uncertainties: the Mahalanobis distance squared of
the disagreement, over the match's stated covariance plus the odometry's
*earned* variances (without the floor), above the chi-square quantile of
``level`` with as many degrees of freedom as trusted components. On such a
step one of them is wrong by more than it says, and the evidence of which
is the variance each has earned along the disagreement's direction ``u``:
the odometry's from its record (``u' diag(earned) u``), the match's from
its own information, i.e. its degeneracy along ``u`` (``u' C u``; a
match in a corridor or a fast turn states a large one). The smaller wins:

* the odometry: its factor gets the earned variance (no floor), and the
  match edge's covariance grows along ``u`` to the disagreement squared,
  the error the match has just shown there (never shrinks);
* the match: no odometry factor for this step (the match stands alone, as
  when today's outlier gate refuses a step).

A step that agrees within ``level``, or that today's outlier gate
(``odometry_trust_gate_chi2``, with the floored variances) refuses, is
judged as before, so the rule only changes the steps between the two tests.
Only what the method measures enters: the matches' stated information and
the innovation record; no reference. Odometry that earned no trust (biased,
or worse than its matches, as on intel's raw log) gets no factor either way.
The first steps of a log, judged once ``min_history`` steps are known, have
their match edges in the graph already: for them only the factor follows
the choice.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph.odometry_trust import (
    UNTRUSTED_VARIANCE,
    OdometryFactors,
    OdometryTrust,
    innovation,
)


@dataclass(frozen=True)
class Choice:
    """One step's judgement: ``kind`` is ``"as before"``, ``"odometry"`` or ``"match"`` (module docstring)."""

    kind: str
    odometry_covariance: FloatArray | None
    match_covariance: FloatArray


def choose(
    trust: OdometryTrust,
    odometry_step: FloatArray,
    match_step: FloatArray,
    match_covariance: FloatArray,
    level: float,
) -> Choice:
    """The odometry factor's covariance (None: no factor) and the match's, for one matched node step."""
    cov = np.asarray(match_covariance, dtype=float)
    before = trust.gated_variances(odometry_step, match_step, cov)
    as_before = Choice(
        "as before",
        None if before is None else np.diag(np.where(np.isfinite(before), before, UNTRUSTED_VARIANCE)),
        cov,
    )
    earned = trust.variances(np.diag(cov), trust.kind(odometry_step), float(odometry_step[2]), floor=False)
    if before is None or earned is None:
        return as_before  # too few steps, nothing trusted, or an outlier by today's gate: as before
    trusted = np.isfinite(earned)
    d = innovation(match_step, odometry_step)[trusted]
    match_t = cov[np.ix_(trusted, trusted)]
    if float(d @ np.linalg.solve(match_t + np.diag(earned[trusted]), d)) <= quantile(level, int(trusted.sum())):
        return as_before  # they agree within what they state
    norm = float(np.linalg.norm(d))
    u = d / norm
    odometry_var = float(u @ (earned[trusted] * u))
    match_var = float(u @ match_t @ u)
    if odometry_var >= match_var:
        return Choice("match", None, cov)
    full_u = np.zeros(3)
    full_u[trusted] = u
    inflated = cov + max(0.0, norm**2 - match_var) * np.outer(full_u, full_u)
    return Choice("odometry", np.diag(np.where(trusted, earned, UNTRUSTED_VARIANCE)), inflated)


@lru_cache(maxsize=16)
def quantile(level: float, dof: int) -> float:
    """The chi-square quantile of ``level`` with ``dof`` degrees of freedom (cached: scipy's costs ~0.1 ms a call).

    ``scipy.stats`` is imported here, not with the module: every gtsam-graph run imports this module, and only
    a run with the setting on asks for a quantile.
    """
    from scipy.stats import chi2

    return float(chi2.ppf(level, dof))


class EarnedFactors(OdometryFactors):
    """:class:`.odometry_trust.OdometryFactors` whose disagreeing steps keep the side that earned it (:func:`choose`).

    Only the newest node's grown match covariance is handed back (:meth:`match_covariance`).
    """

    def __init__(self, trust: OdometryTrust, level: float, counters: dict[str, int]) -> None:
        """``counters``: the mapper's; ``odometry_earned_odometry`` / ``odometry_earned_match`` count the choices
        and appear only once one is made (a run without any keeps its counters as before)."""
        super().__init__(trust)
        self.level = level
        self.counters = counters
        self._match_covariances: dict[int, FloatArray] = {}

    def judge(
        self, key: int, odometry_step: FloatArray, match_step: FloatArray, match_covariance: FloatArray
    ) -> FloatArray | None:
        """The step's odometry factor covariance after :func:`choose`; an inflated match covariance is kept for
        :meth:`match_covariance`."""
        choice = choose(self.trust, odometry_step, match_step, match_covariance, self.level)
        if choice.kind != "as before":
            name = f"odometry_earned_{choice.kind}"
            self.counters[name] = self.counters.get(name, 0) + 1
        if choice.kind == "odometry":
            self._match_covariances[key] = choice.match_covariance
        return choice.odometry_covariance

    def match_covariance(self, key: int, covariance: FloatArray) -> FloatArray:
        """Node ``key``'s match covariance, grown along the disagreement where the odometry won (else unchanged).

        Asked for the newest node only: earlier steps judged late have their
        edges in the graph already, so what was kept for them is dropped.
        """
        kept = self._match_covariances.get(key, covariance)
        self._match_covariances.clear()
        return kept
