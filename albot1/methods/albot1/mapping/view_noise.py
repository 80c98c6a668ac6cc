"""Albot1+'s view noise: how far a view's fit strays from a prediction it does not refute.

The adaptive prior learns the odometry's spread from the disagreement ``nu`` between a view's fit and the
odometry's prediction (:class:`~albot1.methods.albot1.mapping.plus.OdometryNoise`). That disagreement holds the
fit's own error as well as the odometry's, and only the views the ambiguity test lets through teach it -- on a
log with good odometry, the views that stray most. On fr-clinic the learnt heading spread came out about ten
times wider than the odometry's (``docs/albot1-mapper.md``, "View noise"), so the fusion kept most of every
weakly supported 2-5 deg departure and the map updates froze them in.

The views the ambiguity test keeps as the prediction measure the other term: there the view does not refute
the odometry, so their disagreement is mostly the fit's own scatter. :class:`ViewNoise` tracks its running
median per position axis and in heading (the learner's own rule, :func:`median_step`: multiplicative steps
towards the samples, divided by the chi-square(1) median), and :meth:`ViewNoise.remove` takes it out of a
teaching view's squared disagreement before the odometry learner sees it:
``E[nu^2] = odometry variance + view variance``. Where the odometry is bad the disagreements are far larger
than the view's scatter and little changes.

A kept view's disagreement is the odometry's error too wherever the fit is precise (on ``intel-corrected
gauss:0.1:1`` the estimate came out at the odometry's own 1 deg per step), and with perfect odometry the fit
states a quarter to a half of the scatter the kept views show (``docs/albot1-mapper.md``, "Why `plus` leaves
perfect odometry"). :meth:`ViewNoise.learn_cross` learns it from a disagreement that holds no odometry: the same
view fitted against the last update view and against the one before it (:mod:`.cross_noise`, for the fit noise
with ``fit_noise_source = "cross"``). Both fits are the view's pose in the map; they differ by the two fits' errors
and by the placement of the last update view relative to the one before, which is the error a map update freezes.
"""

from __future__ import annotations

import math

from albot1.geometry.se2 import Pose, wrap_angle

#: The median of a chi-square variable with one degree of freedom, in units of its mean.
CHI2_1_MEDIAN = 0.45493642
#: Starting variances (m^2 per position axis, rad^2): 1 mm and 0.01 rad; the median moves off them in a few dozen views.
START = (1e-6, 1e-4)
#: What is left of a squared disagreement at least (m^2, rad^2): a teaching view always teaches something.
FLOOR = (1e-12, 1e-14)


def median_step(value: float, sample: float, step: float) -> float:
    """``value`` moved one multiplicative step (``exp(+-step)``) towards making it the running median of ``sample``.

    The rule both of Albot1+'s noise learners use (:class:`ViewNoise`, ``plus.OdometryNoise``): up when the
    sample exceeds the chi-square(1) median of a variable of variance ``value``, down otherwise; a median, unlike
    a mean, is not moved by the occasional mismatched view.
    """
    return value * math.exp(step if sample > CHI2_1_MEDIAN * value else -step)


class ViewNoise:
    """The running median of the squared disagreement in views that do not refute the odometry's prediction."""

    def __init__(self, learning_rate: float) -> None:
        self.step = 2.0 * learning_rate
        self.variance = list(START)

    def learn(self, measured: Pose, predicted: Pose) -> None:
        """One view kept as the prediction by the ambiguity test: its fit ``measured`` against ``predicted``."""
        nu2_xy = 0.5 * ((measured[0] - predicted[0]) ** 2 + (measured[1] - predicted[1]) ** 2)
        d_phi = wrap_angle(measured[2] - predicted[2])
        for g, nu2 in ((0, nu2_xy), (1, d_phi * d_phi)):
            self.variance[g] = median_step(self.variance[g], nu2, self.step)

    def learn_cross(self, first: Pose, second: Pose) -> None:
        """One view fitted twice, against two update views: half the squared difference is one fit's variance.

        Two independent errors of variance ``v`` differ by a variance ``2 v``; a position sample averages the two
        axes, as :meth:`learn`'s does.
        """
        nu2_xy = 0.25 * ((first[0] - second[0]) ** 2 + (first[1] - second[1]) ** 2)
        d_phi = wrap_angle(first[2] - second[2])
        for g, nu2 in ((0, nu2_xy), (1, 0.5 * d_phi * d_phi)):
            self.variance[g] = median_step(self.variance[g], nu2, self.step)

    def remove(self, nu2_xy: float, nu2_phi: float) -> tuple[float, float]:
        """A teaching view's squared disagreement (per position axis, m^2; heading, rad^2) less the view's own."""
        return max(nu2_xy - self.variance[0], FLOOR[0]), max(nu2_phi - self.variance[1], FLOOR[1])
