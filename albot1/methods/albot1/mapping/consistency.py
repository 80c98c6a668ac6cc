"""Albot1+'s consistent information: a view's fit weighs only as much as its own cost says it knows.

The pose fit's information matrix (``J^T W J`` of its landmark and scan terms) treats every scan point as an
independent measurement with the stated ``scan_sigma``. Points of one surface are not independent (they share
that surface's fit error), and a view of a few short surfaces fixes its heading far worse than 150 points say:
on fr-clinic a view that turns 3 deg away from the odometry states a heading sigma of 0.1 deg, so the fusion
with the odometry's prediction keeps nearly all of the turn, and the next map update freezes it
(``docs/albot1-mapper.md``, "Consistent information").

The ambiguity test (:mod:`.ambiguity`) already measures how strongly the view refutes the prediction: its
likelihood ratio ``statistic`` (the robust cost at the prediction minus at the fit, in the fit's own residual
variance, per independent term). Were the fit Gaussian with information ``I``, that ratio would be the
squared Mahalanobis distance ``d^T I d`` of the disagreement ``d``. Where the stated distance is larger than
the measured ratio, the stated information overstates what the view knows along ``d``; :func:`information_scale`
returns the factor that makes the two agree (never above 1), and the fusion scales the fit's information by it.
A view that refutes the odometry strongly (bad odometry, a ratio in the hundreds) keeps most of its weight; a
view that only just refutes it is weighed like the odometry it barely disagrees with. Nothing is thresholded:
the factor moves the fused pose continuously between the fit and the prediction.
"""

from __future__ import annotations

import math

from albot1.geometry.se2 import Pose, wrap_angle
from albot1.geometry.types import FloatArray


def stated_distance(info: FloatArray, measured: Pose, predicted: Pose) -> float:
    """``d^T info d``: the squared Mahalanobis distance of ``measured`` from ``predicted`` by the fit's ``info``.

    ``info``: 3x3 (position in m, heading in rad); the heading difference is wrapped.
    """
    dx = measured[0] - predicted[0]
    dy = measured[1] - predicted[1]
    dp = wrap_angle(measured[2] - predicted[2])
    return float(
        info[0, 0] * dx * dx
        + info[1, 1] * dy * dy
        + info[2, 2] * dp * dp
        + 2.0 * (info[0, 1] * dx * dy + info[0, 2] * dx * dp + info[1, 2] * dy * dp)
    )


def information_scale(statistic: float, stated: float, factor: float = 1.0) -> float:
    """The factor (in (0, 1]) the fit's information is scaled by: ``factor * statistic / stated``, at most 1.

    ``statistic``: the view's likelihood ratio against the prediction (:func:`.ambiguity.view_ambiguity`);
    ``stated``: :func:`stated_distance`; ``factor`` (``consistent_information``): how many times the ratio the
    stated distance may be before the information is scaled. ``factor <= 0`` or ``stated`` not positive and
    finite: 1 (nothing to scale, or the rule off).
    """
    if factor <= 0.0 or not (0.0 < stated < math.inf):
        return 1.0
    return min(1.0, max(factor * statistic, 0.0) / stated)
