"""Albot1+'s noise split: the odometry's spread and the views' own, told apart by how they grow with motion.

The adaptive prior learns the odometry's spread from the disagreement ``nu`` between a view's fit and the
odometry's prediction since the last update (``plus.OdometryNoise``). ``nu`` holds both errors:
``E[nu^2] = V + q s`` per position axis and in heading, with ``s`` the motion since the update (a turn counting
``m_per_rad`` per radian), ``q`` the odometry's random-walk variance per metre and ``V`` the fit's own error,
which does not grow with ``s``. The median learner attributes all of ``nu^2 / s`` to the odometry, so with
perfect odometry its spread never falls below the views' scatter; the view noise (:mod:`.view_noise`) takes out
the scatter of the views that do not refute the odometry, but those views' disagreement is the odometry's error
too wherever the fit is precise, so on noisy odometry it removes part of the odometry's own spread. Neither can
tell the two apart from one sample.

Many samples can: the views just after an update measure ``V`` (``s`` near 0), the views far from it ``V + q s``.
:class:`NoiseSplit` fits that line by least squares over the teaching views, forgetting old samples
exponentially (a memory of ``samples`` views), with each squared disagreement clipped at
:data:`CLIP` times the line's current value there (a mismatched view must not carry the fit; the chi-square(1)
tail beyond 9 holds 0.3 % of honest samples). The intercept is the views' noise, the slope the odometry's.
The fusion then weighs the fit by its stated covariance plus ``V``
(:func:`~albot1.methods.albot1.mapping.fit_noise.with_fit_noise`) and the prediction by ``floor + q s``:
consistent odometry earns a spread below the views' and the fusion follows it; where the odometry errs, ``q``
grows and the views win as before. Only the method's own measurements are used.
"""

from __future__ import annotations

#: Squared disagreements are clipped at this multiple of the line's value at their motion.
CLIP = 9.0
#: Effective samples (sum of the forgetting weights) before the line replaces the start values.
MIN_WEIGHT = 10.0


class NoiseSplit:
    """``E[nu^2] = V + q s`` fitted per group (position axis, heading) over the teaching views."""

    def __init__(
        self, samples: int, start_q: tuple[float, float], start_v: tuple[float, float], floor: tuple[float, float]
    ) -> None:
        self.floor = floor  # the prior's variance floors (m^2, rad^2)
        self.keep = 1.0 - 1.0 / samples
        self.q = list(start_q)  # the odometry's variance per metre of motion (m^2 / m, rad^2 / m)
        self.variance = list(start_v)  # the views' own variance (m^2 per axis, rad^2)
        # per group: sum w, w s, w s^2, w y, w s y
        self._sums = [[0.0] * 5, [0.0] * 5]
        self.samples = 0

    def learn(self, nu2_xy: float, nu2_phi: float, motion: float) -> None:
        """One teaching view's squared disagreement (per position axis, m^2; heading, rad^2) after ``motion``."""
        self.samples += 1
        for g, nu2 in ((0, nu2_xy), (1, nu2_phi)):
            line = self.variance[g] + self.q[g] * motion
            y = min(nu2, CLIP * line) if line > 0.0 else nu2
            sums = self._sums[g]
            k = self.keep
            sums[0] = k * sums[0] + 1.0
            sums[1] = k * sums[1] + motion
            sums[2] = k * sums[2] + motion * motion
            sums[3] = k * sums[3] + y
            sums[4] = k * sums[4] + motion * y
            if sums[0] >= MIN_WEIGHT:
                self.variance[g], self.q[g] = _line(sums)

    def prior_variance(self, motion: float) -> tuple[float, float]:
        """Variance (m^2 per axis, rad^2) of the odometry's prediction after ``motion``: ``floor + q s``."""
        return (self.floor[0] + self.q[0] * motion, self.floor[1] + self.q[1] * motion)


def _line(sums: list[float]) -> tuple[float, float]:
    """Least-squares ``(intercept, slope)`` of ``y`` on ``s`` from the weighted sums, both held non-negative."""
    w, s, ss, y, sy = sums
    det = w * ss - s * s
    if det <= 1e-12 * w * ss:  # every sample at one motion: the mean is the odometry's at that motion
        return 0.0, max(y / s, 0.0) if s > 0.0 else 0.0
    intercept = (ss * y - s * sy) / det
    slope = (w * sy - s * y) / det
    if intercept < 0.0:  # through the origin: all of it is the odometry's
        return 0.0, max(sy / ss, 0.0)
    if slope < 0.0:  # flat: all of it is the views'
        return max(y / w, 0.0), 0.0
    return intercept, slope
