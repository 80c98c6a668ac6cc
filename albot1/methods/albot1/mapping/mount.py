"""Albot1+'s mount calibration: where the odometry's frame sits on the scanner, learnt from the views.

A laser mounted away from where the odometry is reported (``offset:DX:DY:DTHETA``, ``albot1/data/degrade.py``)
makes every odometry increment ``O`` that of a displaced frame: the scanner's increment is ``M = D O D^-1`` for
the unknown mount ``D = (d, delta)``. The headings agree; the translations differ by ``(I - R(theta)) d`` on a
turn ``theta`` (about ``|d| theta``) and by the direction ``delta`` along a straight step. The odometry's
prediction since the last update view is then off on every turn, and the views correct it by fits that carry
their own error (``docs/albot1-mapper.md``, "The wrong laser offset").

Writing ``R(delta) = [[c, -s], [s, c]]``, the translation of ``M D = D O`` is linear in ``u = (dx, dy, c, s)``::

    t_M = (I - R(theta)) d + R(delta) t_O

(a planar hand-eye calibration). :class:`MountCalibration` keeps the normal equations of that least squares over
the views that fix their pose on their own (the odometry learner's teaching views), each weighted by the inverse
of the prediction's variance at that view, with a Gaussian prior at the identity mount (``prior_m`` per position
axis, :data:`PRIOR_RAD` in the mount's turn): the degeneracy-aware part -- ``d`` is learnt only from turns, the
direction only from translations, and where neither has been seen the mount stays at the identity.
:meth:`MountCalibration.correct` turns an odometry increment into the scanner's, ``D O D^-1``, while the estimate
explains at least :data:`EXPLAINED` of the weighted squared disagreement (else the increment is left as it came:
a mount that explains little is the odometry's own error fitted). The disagreement counts the heading too (at
``m_per_rad`` metres per radian, the prior's own exchange rate): a mount leaves the headings equal, so a heading
disagreement is error no mount explains. Without it the mount came on on intel's raw log, whose odometry has a
systematic heading error that a turned mount half explains in translation (``docs/albot1-mapper.md``, "The wrong
laser offset, again").
"""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry.se2 import Pose, wrap_angle

#: Prior standard deviation of the mount's turn (rad): a laser mounted within about 6 deg of the odometry's axis.
PRIOR_RAD = 0.1
#: The mount is applied only while it explains at least this share of the weighted squared disagreement between the
#: odometry's and the views' translations (a mount that explains little is the odometry's own error fitted).
EXPLAINED = 0.5
#: Teaching views between two solves of the 4x4 normal equations (the sums are kept at every view).
SOLVE_EVERY = 8


class MountCalibration:
    """The odometry-to-scanner mount ``D``, estimated online (see the module docstring)."""

    def __init__(self, prior_m: float, m_per_rad: float = 0.0) -> None:
        """``prior_m``: the prior sd of the mount's position; ``m_per_rad``: a heading disagreement's weight."""
        self._m_per_rad = m_per_rad
        self._heading_residual = 0.0  # sum of w (m_per_rad * heading disagreement)^2: no mount explains it
        self._prior = (1.0 / prior_m**2, 1.0 / PRIOR_RAD**2)
        # Normal equations A^T W A (upper triangle, row-major) and A^T W b, prior included; u0 = (0, 0, 1, 0).
        self._ata = [self._prior[0], 0.0, 0.0, 0.0, self._prior[0], 0.0, 0.0, self._prior[1], 0.0, self._prior[1]]
        self._atb = [0.0, 0.0, self._prior[1], 0.0]
        self._btb = self._prior[1]  # sum of w |t_M|^2 (and the prior's target), for the residual at the estimate
        self._identity_residual = 0.0  # sum of w |t_M - t_O|^2: the residual of the identity mount
        #: The estimate explains at least :data:`EXPLAINED` of the disagreement: :meth:`correct` applies it.
        self.active = False
        #: The share of the weighted squared disagreement the estimate explains (at the last solve).
        self.explained = 0.0
        self.samples = 0
        #: The current estimate: mount position (m, the increment's frame) and the rotation's cosine and sine.
        self.dx = 0.0
        self.dy = 0.0
        self.cos = 1.0
        self.sin = 0.0

    def learn(self, odometry: Pose, measured: Pose, weight: float) -> None:
        """One view: the odometry's increment since the update and the view's own (the update view's frame)."""
        th = odometry[2]
        a = 1.0 - math.cos(th)
        b = math.sin(th)
        ox, oy = odometry[0], odometry[1]
        mx, my = measured[0], measured[1]
        # Rows (a, b, ox, -oy | mx) and (-b, a, oy, ox | my).
        m, v = self._ata, self._atb
        m[0] += weight * (a * a + b * b)
        m[2] += weight * (a * ox - b * oy)
        m[3] += weight * (-a * oy - b * ox)
        m[4] += weight * (b * b + a * a)
        m[5] += weight * (b * ox + a * oy)
        m[6] += weight * (-b * oy + a * ox)
        m[7] += weight * (ox * ox + oy * oy)
        m[9] += weight * (oy * oy + ox * ox)
        v[0] += weight * (a * mx - b * my)
        v[1] += weight * (b * mx + a * my)
        v[2] += weight * (ox * mx + oy * my)
        v[3] += weight * (-oy * mx + ox * my)
        self._btb += weight * (mx * mx + my * my)
        self._identity_residual += weight * ((mx - ox) ** 2 + (my - oy) ** 2)
        self._heading_residual += weight * (self._m_per_rad * wrap_angle(measured[2] - th)) ** 2
        self.samples += 1
        if self.samples % SOLVE_EVERY == 0:
            self._solve()

    def _solve(self) -> None:
        m = self._ata
        full = np.array(
            [
                [m[0], m[1], m[2], m[3]],
                [m[1], m[4], m[5], m[6]],
                [m[2], m[5], m[7], m[8]],
                [m[3], m[6], m[8], m[9]],
            ]
        )
        atb = np.asarray(self._atb)
        u = np.linalg.solve(full, atb)
        dx, dy, c, s = u.tolist()
        norm = math.hypot(c, s)
        if not norm > 0.0:  # no rotation can be read off: keep the last estimate
            return
        residual = self._btb - 2.0 * float(u @ atb) + float(u @ full @ u)
        heading = self._heading_residual
        total = self._identity_residual + heading
        self.explained = 1.0 - (residual + heading) / total if total > 0.0 else 0.0
        self.active = self.explained >= EXPLAINED
        self.dx, self.dy, self.cos, self.sin = dx, dy, c / norm, s / norm

    def correct(self, odometry: Pose) -> Pose:
        """The scanner's increment ``D O D^-1`` for the odometry's increment ``O`` (the heading is unchanged)."""
        if not self.active:
            return odometry
        th = odometry[2]
        a = 1.0 - math.cos(th)
        b = math.sin(th)
        c, s = self.cos, self.sin
        x = a * self.dx + b * self.dy + c * odometry[0] - s * odometry[1]
        y = -b * self.dx + a * self.dy + s * odometry[0] + c * odometry[1]
        return (x, y, th)
