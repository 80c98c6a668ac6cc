"""The odometry's heading over runs of node steps as its own factor (``odometry_trust_run_nodes``; measured, off:
docs/baselines.md, gtsam-graph, "edges spanning runs of steps").

The per-step odometry factors (:class:`.odometry_trust.OdometryFactors`)
judge the odometry one node step at a time, with a weight floor: a step's
odometry never outweighs its match. Over one step a perfect odometry and a
wheel odometry that slips in turns look alike (fr-clinic's straight steps
spread 0.26 deg against its matches, edmonton's perfect odometry 0.48 deg:
both below the matches' stated 0.5 deg), so the floor must hold for both,
and with perfect odometry it leaves half of each match's heading error in
the map (docs/baselines.md, "where edmonton's 0.30 m is"). Over a run of
``m`` steps they differ: a wheel odometry's errors in turns are steady
(a scale error) and add up as ``m`` times themselves, while the matches'
errors partly cancel (lag-1 autocorrelation -0.27 on edmonton) and a
perfect odometry has none. Here the same learning as per step
(:class:`.odometry_trust.OdometryTrust`: robust spread, bias test, bias
horizon, chi-square gate, weight floor) is applied to non-overlapping runs
of ``m`` matched node steps: the run's odometry heading against the chain
of its ``m`` matches, the chain's stated variance being the sum of theirs.
A run that passes becomes one heading factor from its first node to its
last (a :class:`.span_edges.SpanEdge`), in addition to the per-step ones.
A fallback (unmatched) step ends the run without a factor. Optionally
(``max_turn_rad``) a run holding a step whose odometry turns more than that
is neither learnt from nor judged: a wheel odometry slips in turns
(fr-clinic's heading spread 2-4x wider there), and turns are rare enough
that the straight runs set the pooled spread.
"""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph.odometry_trust import OdometryFactors, OdometryTrust
from albot1.methods.baselines.gtsam_graph.span_edges import SpanEdge


class OdometryRuns:
    """Non-overlapping runs of ``nodes`` matched node steps, judged as one odometry step each (module docstring)."""

    def __init__(self, trust: OdometryTrust, nodes: int, max_turn_rad: float = math.inf) -> None:
        """``trust`` learns from and judges the runs (its own history: runs, not steps); ``nodes``: steps per run;
        ``max_turn_rad``: runs holding a step whose odometry turns more than this are left out (``inf``: none)."""
        self.nodes = nodes
        self.max_turn_rad = max_turn_rad
        self._factors = OdometryFactors(trust)
        self._first: dict[int, int] = {}
        self._start = -1
        self._odometry = np.zeros(3)
        self._match = np.zeros(3)
        self._variances = np.zeros(3)
        self._turn = 0.0
        self._steps = 0

    def add(
        self, key: int, odometry_step: FloatArray, match_step: FloatArray, match_covariance: FloatArray
    ) -> list[SpanEdge]:
        """Node ``key``'s matched step; the run factors that can now be judged and passed (usually none)."""
        if self._steps == 0:
            self._start = key - 1
        self._odometry = se2.compose(self._odometry, np.asarray(odometry_step, dtype=float))
        self._match = se2.compose(self._match, np.asarray(match_step, dtype=float))
        self._variances = self._variances + np.diag(np.asarray(match_covariance, dtype=float))
        self._turn = max(self._turn, abs(float(odometry_step[2])))
        self._steps += 1
        if self._steps < self.nodes:
            return []
        if self._turn > self.max_turn_rad:
            self.reset()
            return []
        self._first[key] = self._start
        factors = self._factors.add(key, self._odometry, self._match, np.diag(self._variances))
        self.reset()
        return [SpanEdge(self._first.pop(f.key), f.key, f.step, f.covariance) for f in factors]

    def reset(self) -> None:
        """End the current run without a factor (a step without a match breaks the chain)."""
        self._odometry = np.zeros(3)
        self._match = np.zeros(3)
        self._variances = np.zeros(3)
        self._turn = 0.0
        self._steps = 0
