"""How much to trust the odometry of a node step, learnt from its disagreement with the scan matches.

On in the default preset (``odometry_trust``; docs/baselines.md, gtsam-graph,
"the accumulated bias and a weight floor": no setting measured keeps
fr-clinic's first return and meets the held-out targets at once), as
separate odometry factors (:class:`OdometryFactors`,
``odometry_trust_factors``). The fused edge
(:meth:`OdometryTrust.fuse`) is the earlier variant, whose result on short
logs swung with when fusion starts (docs/baselines.md, gtsam-graph,
"Held-out logs ... the odometry as its own factor").

A node's sequential edge is its scan match; the odometry only enters as the
match's weak start prior (``odometry_sigma_*``, 5 deg per node step). Where
the odometry is good that throws it away: on edmonton-corrected with perfect
odometry every match is off the true step by 0.48 deg RMS (0.05 m) and
those errors add up along the graph as a random walk of heading (ATE 0.54 m).
The match is not wrong beyond its stated floor (``match_sigma_floor_*``);
the odometry was simply better.

How good the odometry is can be read from the innovations, the differences
between the odometry step and the match (covariance matching, Mehra 1972):
their spread is the odometry's variance plus the match's, so the odometry's
is what the spread holds beyond the match's stated covariance. The
estimate is robust (median and MAD over the last ``window`` matched node
steps, so a stalled odometry's catch-up jumps or one bad match do not
inflate it) and never below its own sampling error (``spread**2 *
sqrt(2 / n)``), so a handful of lucky agreements cannot make the odometry
rigid.

Fusing treats the odometry's error as white noise, which a *systematic*
error is not: a constant heading bias fused at half weight would still turn
the map by half the bias at every step. A component (x, y or heading) whose
innovations have a median further from zero than ``bias_z`` standard errors
is therefore not fused (the edge keeps the match alone there): only
odometry that is unbiased by the evidence is trusted, and nothing is fused
before that test has seen enough steps to find a bias as large as the
innovations' spread (:func:`min_history`). A bias too small for that test
still counts: over ``bias_horizon`` steps a steady error ``b`` turns the
map by ``bias_horizon * b`` where white noise of that size turns it by
``sqrt(bias_horizon) * b``, so the squared bias (:func:`squared_bias`)
times ``bias_horizon`` is added to the odometry's variance. Without it an
odometry 0.13 deg per node step off (the synthetic office loop; innovation
spread 0.25 deg, so the median test's 3 standard errors are 0.13 deg)
got a variance at its sampling floor, outweighed the matches ~20 to 1 and
kept the loop from closing (ATE 0.038 -> 0.222 m). And a trusted
component's variance is never below ``min_variance_ratio`` times the
match's: with ``1`` the odometry never outweighs the match it is checked
against (without that floor fr-clinic's first return was lost, 1.96 m). Nor is a component
whose odometry variance comes out above the match's: where the odometry is
the worse of the two, its errors are rarely white either (wheel odometry
slips in turns, drifts slowly, stalls), and fusing it at the weight its
median spread earns cost the standard logs accuracy (intel 0.0159 ->
0.020 m, aces 0.035 -> 0.040 m mean relation error), so there the match
alone stands, as before. The translation is not fused at all in the
default preset (``odometry_trust_translation``): it is the heading that
random-walks into the map through the lever arm of the path, and fusing
the translation too cost intel's raw odometry 7 % (0.016 -> 0.017 m on its
first 1500 scans) where the heading alone changed nothing. Finally one node's
fusion is gated: when the odometry step and the match disagree by more than
their joint covariance allows (Mahalanobis distance squared above
``gate_chi2``), one of them is an outlier and the match stands, as before.

Also optional (``translation_follows_heading``, off in the default preset): the
translation trusted wherever the heading is, at the variance its innovations
earn (never below the floor), without comparing it with the match's claim, and
each step gated on its heading alone. The match's claimed translation variance
is the floor (``match_sigma_floor_xy_m``, ICP's own is far smaller), and with
perfect odometry its real errors are 1.5-2.3x that in variance on
edmonton-corrected and infinite-corridor-corrected (the heading's claim holds:
0.56-0.68), so covariance matching blames the odometry for the match's excess
and a perfect odometry's translation is never, or only now and then, trusted;
the heading, whose claim is calibrated, decides instead (docs/baselines.md,
gtsam-graph, "where the error with perfect odometry comes from").

Optionally (``turn_rad``, off in the default preset) turns and straight
steps are learnt apart (:meth:`OdometryTrust.kind`): a step is then judged
with the larger of the pooled variance and its own kind's, without the
floor once its kind has ``kind_min_steps`` steps. It keeps fr-clinic's
return without the floor, but measured no better everywhere
(docs/baselines.md, gtsam-graph, "turns learnt apart"). Also optional
(``floor_turn_rad``, off: 0) is a floor held only on turning steps
(:meth:`OdometryTrust.floor_ratio`), measured and left off for the same reason
(docs/baselines.md, gtsam-graph, "why one run of edmonton swings"). And
optional (``turn_scale``, off in the default preset) is a heading scale error
learnt from every step of the run (:class:`.odometry_scale.TurnScale`): the
error a mis-scaled odometry makes in proportion to each turn, which the median
test cannot see, is added to that step's variance (docs/baselines.md,
gtsam-graph, "the turn scale").
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph.odometry_scale import TurnScale

#: MAD of a normal sample times this is its standard deviation.
MAD_TO_SIGMA = 1.4826
#: The standard error of a normal sample's median is this times sigma / sqrt(n).
MEDIAN_EFFICIENCY = math.sqrt(math.pi / 2.0)
#: Variance (m^2 or rad^2) of an odometry factor's component that is not trusted: a 1000 m / rad sigma, which
#: carries no information a pose graph notices, in place of the zero information a fused edge gives it.
UNTRUSTED_VARIANCE = 1.0e6


@dataclass(frozen=True)
class OdometryFactor:
    """The odometry step from node ``key - 1`` to node ``key`` as its own between factor, with its learnt covariance."""

    key: int
    step: FloatArray
    covariance: FloatArray


class OdometryTrust:
    """The innovation history of matched node steps and the odometry covariance it supports (module docstring)."""

    def __init__(
        self,
        window: int,
        bias_z: float,
        gate_chi2: float,
        components: tuple[int, ...] = (0, 1, 2),
        bias_horizon: int = 0,
        min_variance_ratio: float = 0.0,
        turn_rad: float = math.inf,
        kind_min_steps: int = 10,
        floor_turn_rad: float = 0.0,
        turn_scale: bool = False,
        translation_follows_heading: bool = False,
    ) -> None:
        """``components``: which of x (0), y (1), heading (2) may be fused at all; ``bias_horizon``: the number of
        steps over which a median disagreement too small for the bias test is counted as accumulating (0: not);
        ``min_variance_ratio``: a trusted component's variance is at least this times its match's; ``turn_rad``:
        steps whose odometry turns more than this are learnt and judged apart from the others (:meth:`kind`;
        ``inf``: one population); ``floor_turn_rad``: the floor holds only for steps whose odometry turns at least
        this much (0: every step; :meth:`floor_ratio`); ``turn_scale``: a heading scale error learnt from every
        step (:class:`.odometry_scale.TurnScale`) adds to each step's heading variance in proportion to its turn;
        ``translation_follows_heading``: x and y are trusted wherever the heading is (:meth:`_estimate`) and a step is
        gated on its heading alone (:meth:`gated_variances`)."""
        self.translation_follows_heading = translation_follows_heading
        self.scale = TurnScale(bias_z, bias_horizon) if turn_scale else None
        self.floor_turn_rad = floor_turn_rad
        self._pooled: deque[FloatArray] = deque(maxlen=window)
        self._kinds: tuple[deque[FloatArray], deque[FloatArray]] = (deque(maxlen=window), deque(maxlen=window))
        # Each history's median and spread, kept until the next step is recorded (several judgements per node
        # read the same history): id of the deque -> (the deque, steps recorded then, centre, spread); the deque is
        # kept and compared, so another history that happens to get a freed one's id is never served its medians
        self._recorded = 0
        self._medians: dict[int, tuple[deque[FloatArray], int, FloatArray, FloatArray]] = {}
        self.turn_rad = turn_rad
        self.kind_min_steps = kind_min_steps
        self.bias_horizon = bias_horizon
        self.min_variance_ratio = min_variance_ratio
        self._min_history = min(window, min_history(bias_z))
        self.bias_z = bias_z
        self.gate_chi2 = gate_chi2
        self.components = components

    def kind(self, odometry_step: FloatArray) -> int:
        """1 for a turn (the odometry's heading step beyond ``turn_rad``), else 0: the population a step belongs to.

        A wheel odometry's heading error is a different population in turns
        than on straight steps (slip grows with the turn), and a turn is rare
        on most routes: learnt together, the straight steps' spread sets the
        turns' weight (fr-clinic: innovation spread 0.26 deg on steps under
        2 deg, 0.6-1.0 deg beyond half a node's rotation step, against the
        matches' 0.51 deg). Each step is therefore learnt and judged with
        the history of its own kind (docs/baselines.md, gtsam-graph, "turns
        learnt apart").
        """
        return 1 if abs(float(odometry_step[2])) > self.turn_rad else 0

    def add(self, odometry_step: FloatArray, match_step: FloatArray) -> None:
        """Record one matched node step's innovation (the match seen from the odometry step), with its kind."""
        d = innovation(odometry_step, match_step)
        self._recorded += 1
        self._pooled.append(d)
        self._kinds[self.kind(odometry_step)].append(d)
        if self.scale is not None:
            self.scale.add(float(odometry_step[2]), float(d[2]))

    def floor_ratio(self, turn_rad: float) -> float:
        """The weight floor of a step whose odometry turns ``turn_rad``: ``min_variance_ratio``, or 0 below the turn.

        The floor keeps a wheel odometry from outweighing the matches where it
        is locally worse than its window shows, which is in turns (wheels slip;
        fr-clinic's heading innovations spread 2-4x wider in turns than on its
        straight steps, docs/baselines.md). On a straight step it also halves
        the weight of an odometry that has earned more: with perfect odometry
        on edmonton the steps whose match is 1-3 deg off are mostly straight,
        and the floor leaves half of each error in the map.
        """
        return self.min_variance_ratio if abs(turn_rad) >= self.floor_turn_rad else 0.0

    def variances(
        self, match_variances: FloatArray, kind: int = 0, turn_rad: float = math.inf, floor: bool = True
    ) -> FloatArray | None:
        """Per component (x, y, theta) the odometry step's variance, ``inf`` where not trusted; None: too few steps.

        ``match_variances`` are the diagonal of the match edge's covariance
        (what the match claims of itself), ``kind`` the step's population
        (:meth:`kind`). Not trusted: no spread, a biased median, or a
        variance not below the match's (module docstring). ``floor=False``:
        what the record alone earns, without the weight floor (:mod:`.earned_choice`).
        """
        if len(self._pooled) < self._min_history:
            return None
        scale = self.scale.variance(turn_rad) if self.scale is not None and math.isfinite(turn_rad) else 0.0
        own = self._kinds[kind]
        if not math.isfinite(self.turn_rad) or len(own) < self.kind_min_steps:
            return self._estimate(self._pooled, match_variances, self.floor_ratio(turn_rad) if floor else 0.0, scale)
        return np.maximum(
            self._estimate(self._pooled, match_variances, 0.0, scale), self._estimate(own, match_variances, 0.0, scale)
        )

    def _estimate(
        self, history: deque[FloatArray], match_variances: FloatArray, floor: float, scale: float = 0.0
    ) -> FloatArray:
        """:meth:`variances` learnt from ``history`` alone, a trusted one never below ``floor`` times the match's;
        ``scale``: the heading variance the turn scale error adds to this step (:class:`.odometry_scale.TurnScale`)."""
        n = len(history)
        known = self._medians.get(id(history))
        if known is not None and known[0] is history and known[1] == self._recorded:
            centre, spread = known[2], known[3]
        else:
            h = np.asarray(history, dtype=float)
            centre = column_medians(h)
            spread = MAD_TO_SIGMA * column_medians(np.abs(h - centre))
            self._medians[id(history)] = (history, self._recorded, centre, spread)
        out = np.full(3, np.inf)
        for k in self.components:
            if spread[k] <= 0.0:
                continue  # no spread measured: nothing to weigh the odometry by
            if abs(centre[k]) > self.bias_z * MEDIAN_EFFICIENCY * spread[k] / math.sqrt(n):
                continue  # systematic: not white noise, not fused
            total = spread[k] ** 2
            variance = max(total - float(match_variances[k]), total * math.sqrt(2.0 / n))
            variance += self.bias_horizon * squared_bias(float(centre[k]), float(spread[k]), n)
            if k == 2:
                variance += scale
            if variance < float(match_variances[k]) or (k < 2 and self.translation_follows_heading):
                # the odometry is the better of the two here (else: the match alone, as tuned); or a translation
                # judged by the heading's verdict below, at the variance it earned (never below the floor)
                out[k] = max(variance, floor * float(match_variances[k]))
        if self.translation_follows_heading and not math.isfinite(out[2]):
            out[:2] = np.inf
        return out

    def fuse(
        self, odometry_step: FloatArray, match_step: FloatArray, match_covariance: FloatArray
    ) -> tuple[FloatArray, FloatArray] | None:
        """The information-weighted mean of the odometry step and the match, and its covariance; None: not fused.

        Not fused when too few steps are known, no component is trusted, or
        the two disagree beyond ``gate_chi2``. Both steps are relative poses
        in the previous node's frame with additive (x, y, theta) errors; the
        heading difference is wrapped.
        """
        variances = self.gated_variances(odometry_step, match_step, match_covariance)
        if variances is None:
            return None
        trusted = np.isfinite(variances)
        odo_info = np.diag(np.where(trusted, 1.0 / np.where(trusted, variances, 1.0), 0.0))
        diff = innovation(match_step, odometry_step)  # odometry minus match, additive
        match_info = np.linalg.inv(match_covariance)
        covariance = np.linalg.inv(match_info + odo_info)
        fused = np.asarray(match_step, dtype=float) + covariance @ (odo_info @ diff)
        fused[2] = math.remainder(fused[2], 2.0 * math.pi)
        return fused, 0.5 * (covariance + covariance.T)

    def gated_variances(
        self, odometry_step: FloatArray, match_step: FloatArray, match_covariance: FloatArray
    ) -> FloatArray | None:
        """The odometry step's per-component variances (``inf``: not trusted) if it may be used at all, else None.

        None when too few steps are known, no component is trusted, or the
        odometry step and the match disagree beyond ``gate_chi2`` on the
        trusted components (their joint covariance).
        """
        variances = self.variances(np.diag(match_covariance), self.kind(odometry_step), float(odometry_step[2]))
        if variances is None or not np.isfinite(variances).any():
            return None
        trusted = np.isfinite(variances)
        if self.translation_follows_heading:
            trusted = np.array([False, False, True])  # the translation's match claim is not to be judged against
        d = innovation(match_step, odometry_step)[trusted]
        joint = np.asarray(match_covariance, dtype=float)[np.ix_(trusted, trusted)] + np.diag(variances[trusted])
        if float(d @ np.linalg.solve(joint, d)) > self.gate_chi2:
            return None
        return variances


class OdometryFactors:
    """The odometry as its own between factor per matched node step, also for the steps before its variance was known.

    :class:`OdometryTrust` fuses a step only once ``min_history`` steps
    have been seen, so the first ones of a log keep the match alone and
    their heading errors stay in the map for good: on short logs the result
    then depends on where fusion starts (edmonton-corrected[::3] with perfect
    odometry: ATE 0.17 / 0.20 / 0.57 / 0.46 m for a start after 10 / 15 /
    26 / 40 steps). Here each matched step is kept until that evidence
    exists and is then judged like any later step (trusted components, bias
    test, chi-square gate) with the variances learnt from all of them: the
    evidence that a step of odometry is good does not depend on whether it
    came before or after the steps that showed it. A step judged untrusted
    gets no factor; one that passes gets a between factor from the previous
    node, whose untrusted components carry :data:`UNTRUSTED_VARIANCE`.
    Unlike a fused edge the factor stays separate from the match in the
    graph, so the graph holds both measurements as they were made.
    """

    def __init__(self, trust: OdometryTrust) -> None:
        self.trust = trust
        self._pending: list[tuple[int, FloatArray, FloatArray, FloatArray]] = []

    def add(
        self, key: int, odometry_step: FloatArray, match_step: FloatArray, match_covariance: FloatArray
    ) -> list[OdometryFactor]:
        """Record node ``key``'s matched step; the factors of every recorded step that can now be judged and passed."""
        self.trust.add(odometry_step, match_step)
        self._pending.append(
            (
                key,
                np.asarray(odometry_step, dtype=float),
                np.asarray(match_step, dtype=float),
                np.asarray(match_covariance, dtype=float),
            )
        )
        if self.trust.variances(np.diag(match_covariance)) is None:
            return []  # too few steps to judge any of them yet
        factors = []
        for k, odo, match, cov in self._pending:
            covariance = self.judge(k, odo, match, cov)
            if covariance is not None:
                factors.append(OdometryFactor(k, odo, covariance))
        self._pending = []
        return factors

    def judge(
        self, key: int, odometry_step: FloatArray, match_step: FloatArray, match_covariance: FloatArray
    ) -> FloatArray | None:
        """Node ``key``'s odometry factor covariance (untrusted components: :data:`UNTRUSTED_VARIANCE`); None: none."""
        variances = self.trust.gated_variances(odometry_step, match_step, match_covariance)
        return None if variances is None else np.diag(np.where(np.isfinite(variances), variances, UNTRUSTED_VARIANCE))

    def match_covariance(self, key: int, covariance: FloatArray) -> FloatArray:
        """Node ``key``'s match edge covariance as judged (here unchanged; :class:`.earned_choice.EarnedFactors`)."""
        return covariance


def min_history(bias_z: float) -> int:
    """Matched steps needed before anything is fused: enough for the bias test to find a bias as large as the spread.

    With ``n`` steps a bias equal to the innovations' spread stands
    ``sqrt(n) / MEDIAN_EFFICIENCY`` standard errors from 0; asking for
    ``bias_z + 2`` of them finds it with 97.7 % power. Fusing earlier, on
    the evidence of 10 steps, let fhw-corrected[::3] under ``bias:0.02:0.5``
    fuse 9 biased headings before the test caught up (ATE 0.16 -> 0.71 m).
    """
    return max(2, math.ceil(((bias_z + 2.0) * MEDIAN_EFFICIENCY) ** 2))


def squared_bias(median: float, spread: float, n: int) -> float:
    """The square of a bias the innovations' ``median`` shows, less what its sampling error alone would give, >= 0.

    A median of ``n`` white innovations with this ``spread`` has a standard
    error of ``MEDIAN_EFFICIENCY * spread / sqrt(n)``; its square is the
    part of ``median**2`` that unbiased odometry shows on average, so only
    the excess is counted as bias (an unbiased estimate of the squared
    bias, clipped at 0).
    """
    standard_error = MEDIAN_EFFICIENCY * spread / math.sqrt(n)
    return max(0.0, median**2 - standard_error**2)


def column_medians(values: FloatArray) -> FloatArray:
    """``np.median(values, axis=0)`` of a 2-D float64 array, the same bits, without the wrapper's overhead.

    The very steps of numpy's ``_median``: ``np.partition`` with the same
    ``kth`` (the middle one or two rows, and the last for its NaN check), then
    the mean of the middle rows as ``np.mean`` computes it (``np.add.reduce``
    divided by the row count). A column with a NaN, or no rows, is left to
    ``np.median`` itself. Called twice per matched node step, where
    ``np.median``'s argument handling cost more than the arithmetic
    (docs/baselines.md, "Cost (issue 24), fifth round").
    """
    n = values.shape[0]
    if n == 0 or values.ndim != 2:
        return np.asarray(np.median(values, axis=0), dtype=np.float64)
    half = n // 2
    kth = [half - 1, half, -1] if n % 2 == 0 else [(n - 1) // 2, -1]
    part = np.partition(values, kth, axis=0)
    if np.isnan(part[-1]).any():
        return np.asarray(np.median(values, axis=0), dtype=np.float64)
    rows = part[half - 1 : half + 1] if n % 2 == 0 else part[half : half + 1]
    medians: FloatArray = np.add.reduce(rows, axis=0) / len(rows)
    return medians


def innovation(reference: FloatArray, other: FloatArray) -> FloatArray:
    """``other - reference`` as additive (x, y) in the shared parent frame and wrapped heading."""
    ref = np.asarray(reference, dtype=float)
    oth = np.asarray(other, dtype=float)
    return np.array([oth[0] - ref[0], oth[1] - ref[1], se2.wrap_angle(float(oth[2] - ref[2]))], dtype=float)
