"""The odometry's heading scale error, learnt from every matched node step of the run so far.

A wheel odometry's heading error is not white where it matters most: a
wrong wheel base or tyre radius over- or under-reports every turn by the
same fraction (a scale error), so its error in a step is proportional to
how far the step turns, and the errors of turns the same way add up. The
median test of :class:`.odometry_trust.OdometryTrust` cannot see it: left
and right turns cancel in the median, and turns are rare on most routes (on
fr-clinic 87 % of the node steps turn less than 2 deg), so a 50-step window
holds too few of them to show anything. Measured on the default run
(heading innovation against the odometry's heading step, :meth:`TurnScale.estimate`
over the whole run): fr-clinic's wheel odometry is off by 1.1 % of each turn
(4.9 standard errors from 0), aces's by 0.95 % (2.4), the synthetic office
worlds' by 1.4-1.7 % (4.3-5.3; its odometry model's ``turn_scale`` is 1.01),
while perfect odometry on the suite's corrected logs shows 0.0-0.25 % (at most
1.9 standard errors). That is a likely reason the weight floor
(``min_variance_ratio``) was needed on fr-clinic: its straight steps earn a
small variance and its turns were judged by it (docs/baselines.md,
gtsam-graph, "turns learnt apart"). Off in the default preset
(``odometry_trust_turn_scale``): with the floor removed it meets edmonton's
targets and keeps fr-clinic's return, but costs seattle, aces, orebro and
acapulco (docs/baselines.md, gtsam-graph, "the odometry's turn scale").

A scale error is a calibration constant of the odometry, so it is learnt
from every step seen, not a window: a prior weak at the start that
sharpens as turns accumulate. It counts only when the estimate stands
``bias_z`` standard errors from 0 (the median test's threshold); then a
step turning ``t`` is expected to be ``scale * t`` off, and as with the
median's bias (:func:`.odometry_trust.squared_bias`) that error, less the
estimate's own sampling error, is counted as accumulated over
``bias_horizon`` steps and added to the step's variance. Straight steps
keep the variance they earned; turns of a mis-scaled odometry lose their
weight in proportion to the turn.
"""

from __future__ import annotations

import math

import numpy as np

#: MAD of a normal sample times this is its standard deviation (as in odometry_trust).
MAD_TO_SIGMA = 1.4826
#: Residuals beyond this many robust standard deviations are clipped there (Huber's usual constant is 1.345; 3 keeps
#: the fit nearly least squares for the normal bulk). Not tuned.
CLIP_SIGMAS = 3.0
#: Refits on the clipped residuals (the slope settles in two or three).
ITERATIONS = 3


class TurnScale:
    """The heading scale error of the odometry (innovation per radian turned) from all matched steps so far."""

    def __init__(self, bias_z: float, bias_horizon: int) -> None:
        self.bias_z = bias_z
        self.bias_horizon = bias_horizon
        self._turns: list[float] = []
        self._innovations: list[float] = []
        self._cached: float | None = None

    def add(self, turn_rad: float, innovation_rad: float) -> None:
        """Record one matched node step: its odometry heading step and its heading innovation (odometry - match)."""
        self._turns.append(float(turn_rad))
        self._innovations.append(float(innovation_rad))
        self._cached = None

    def estimate(self) -> tuple[float, float]:
        """The scale error (rad of innovation per rad turned) and its standard error; (0, inf) without evidence.

        Least squares through the origin, made robust by winsorising: the
        residuals are clipped at ``CLIP_SIGMAS`` robust standard deviations
        (1.4826 MAD) and the slope refitted, ``ITERATIONS`` times (a bad
        match in a turn would otherwise pull the slope by its full size; the
        innovations themselves are not clipped, since a mis-scaled odometry's
        large turns are off by large amounts on purpose). The standard error
        is the heteroscedasticity-consistent one of the clipped residuals
        (White's): the innovations spread wider in turns than on straight
        steps, even with perfect odometry (the matches' own errors grow), so
        the straight steps' spread would understate it.
        """
        t = np.asarray(self._turns, dtype=float)
        d = np.asarray(self._innovations, dtype=float)
        turned = float(t @ t)
        if len(t) < 2 or turned <= 0.0:
            return 0.0, math.inf
        scale = float(t @ d) / turned
        clipped = d - scale * t
        for _ in range(ITERATIONS + 1):
            residual = d - scale * t
            spread = MAD_TO_SIGMA * float(np.median(np.abs(residual - np.median(residual))))
            if spread <= 0.0:
                return 0.0, math.inf
            clipped = np.clip(residual, -CLIP_SIGMAS * spread, CLIP_SIGMAS * spread)
            scale += float(t @ clipped) / turned
        return scale, math.sqrt(float((t * t) @ (clipped * clipped))) / turned

    def squared_scale(self) -> float:
        """The squared scale error if the estimate stands ``bias_z`` standard errors from 0, less its sampling
        error's square; else 0 (cached until the next :meth:`add`)."""
        if self._cached is None:
            scale, standard_error = self.estimate()
            significant = math.isfinite(standard_error) and abs(scale) > self.bias_z * standard_error
            self._cached = max(0.0, scale**2 - standard_error**2) if significant else 0.0
        return self._cached

    def variance(self, turn_rad: float) -> float:
        """The heading variance (rad^2) a step turning ``turn_rad`` gets from the scale error, accumulated over
        ``bias_horizon`` steps (module docstring); 0 for no significant scale error or no turn."""
        return self.bias_horizon * self.squared_scale() * turn_rad**2
