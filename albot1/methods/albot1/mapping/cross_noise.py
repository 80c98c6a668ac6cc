"""Albot1+'s cross fit noise: a view's scatter from two fits of it, against two update views, with no odometry.

The fit noise (:mod:`.fit_noise`) adds the views' scatter to a fused fit's covariance. The view noise it used
(:class:`~.view_noise.ViewNoise` as the kept views teach it) is their disagreement with the odometry's
prediction, so it holds the odometry's error too wherever the fit is precise: on ``intel-corrected
gauss:0.1:1`` it came out at 1.0 deg, the odometry's own noise per step, and the fusion then damped the views
that correct that odometry (``docs/albot1-mapper.md``, "Why `plus` leaves perfect odometry").
:class:`CrossFit` keeps the update view before the last, fits each view that fixes its pose against it as well
(its scan points only: the landmarks' map copies are the last update view's), and teaches a view noise of its
own half the squared difference of the two fits (:meth:`~.view_noise.ViewNoise.learn_cross`). The two poses
differ by the two fits' errors and by the last update view's placement relative to the one before -- the error
a map update freezes -- and by no odometry. It costs one more pose fit per such view.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from albot1.geometry.se2 import Pose
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.mapping.plus_params import PlusParams
from albot1.methods.albot1.mapping.view_noise import ViewNoise

#: A fit fixes its pose when its information exceeds this per m^2 (worst position direction) and per rad^2: the
#: odometry learner's rule (``docs/albot1-mapper.md``, "Albot1+"), shared with it.
LEARN_MIN_INFO = 400.0


def fixes(rows: list[list[float]]) -> bool:
    """Whether a fit of this 3x3 information (nested lists) fixes every direction beyond :data:`LEARN_MIN_INFO`.

    Elsewhere its disagreement with another pose is the fit's slack, not an error anything can learn from.
    """
    (h00, h01, _), (_, h11, _), (_, _, h22) = rows
    # The smaller eigenvalue of the position block: how well the worst-fixed direction is known.
    half_trace = 0.5 * (h00 + h11)
    min_xy = half_trace - math.sqrt(max(0.0, half_trace * half_trace - (h00 * h11 - h01 * h01)))
    return min_xy > LEARN_MIN_INFO and h22 > LEARN_MIN_INFO


class CrossFit:
    """The update view before the last, and the view noise learnt from fits against it (module docstring)."""

    def __init__(self, params: PlusParams, refine_pose: Callable[..., Any]) -> None:
        self.params = params
        self._refine_pose = refine_pose
        self.noise = ViewNoise(params.view_noise_rate)
        self._previous = np.empty((0, 4))
        self._no_landmarks = np.empty((0, 4))
        self._no_points = np.empty((0, 2), dtype=np.bool_)

    def reset(self, last: FloatArray) -> None:
        """A map update: ``last`` (the update view it replaces, in the map) is the one views are fitted against too."""
        self._previous = last

    def learn(self, measured: Pose, info: FloatArray, points: FloatArray) -> None:
        """Fit the view's ``points`` against the update view before the last; teach the difference from ``measured``.

        ``measured`` / ``info``: its fit against the last update view and that fit's information. Only where both
        fits fix every direction (:func:`fixes`); the second fit starts from the first.
        """
        if self._previous.shape[0] == 0 or not fixes(info.tolist()):
            return
        p = self.params
        empty = self._no_landmarks
        x, y, phi, other = self._refine_pose(
            np.array([measured]),
            empty,
            empty,
            self._no_points,
            points,
            self._previous,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            p.line_sigma,
            p.point_sigma,
            p.scan_sigma,
            p.huber,
            p.scan_gate,
            p.iterations,
            p.overhang,
        )
        if fixes(other.tolist()):
            self.noise.learn_cross(measured, (x, y, phi))
