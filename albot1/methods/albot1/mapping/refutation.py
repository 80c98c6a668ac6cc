"""Albot1+'s refutation test: does a view's disagreement with the odometry exceed what the view's own noise explains?

With perfect odometry every departure of ``plus`` from the odometry is an error of its own, and it comes from
the views the ambiguity test lets through (:mod:`.ambiguity`): there the fit is fused with the odometry's
prediction, the fit's stated information (``J^T W J`` over hundreds of scan points, each counted as independent)
out-votes the prediction, and the next map update freezes the departure into the map. The odometry learner
cannot fix the weights: its samples are view-versus-odometry disagreements, so its spread never falls below the
views' own scatter, and the prior's floor keeps it above a centimetre and a milliradian anyway.

The ambiguity test asks whether the view's *cost* tells the fit from the prediction, in units of the fit's own
residuals. This test asks the question of the poses: under the hypothesis that the prediction is the true pose,
the disagreement ``d = fit - prediction`` is the fit's error, whose covariance is the fit's stated covariance
plus the views' measured scatter (:class:`~.view_noise.ViewNoise`, learnt from the views that do not refute the
odometry). Its Mahalanobis distance :func:`refutation_statistic` is chi-square with three degrees of freedom; at
or below ``refutation_probability``'s quantile the view does not refute the odometry beyond its own noise, and
the prediction is kept (and teaches the odometry learner, as the ambiguity test's kept views do).

Where the odometry is off by more than the views' scatter (a wrong mount, a bias, Gaussian noise), the
disagreement is far beyond the quantile and the view is fused as before. Only what the method measures is used:
the fit, its information, the prediction and the learnt view noise.
"""

from __future__ import annotations

from collections.abc import Sequence

from albot1.geometry.se2 import Pose, wrap_angle
from albot1.methods.albot1.mapping.fit_noise import Information, with_fit_noise


def refutation_statistic(measured: Pose, info: Information, predicted: Pose, variance: Sequence[float]) -> float:
    """``d^T (info^-1 + V)^-1 d``: the fit's departure from the prediction in units of the view's error.

    ``info``: the fit's information ``(h00, h01, h02, h11, h12, h22)`` (position m, heading rad);
    ``variance``: the view noise ``(m^2 per position axis, rad^2)``, ``V = diag(v_xy, v_xy, v_phi)``. The inverse
    of ``info^-1 + V`` is :func:`~.fit_noise.with_fit_noise`'s (one implementation; it needs no inverse of ``info``).
    A direction the fit leaves free (no information) has infinite variance there: a departure along it refutes
    nothing, as the fusion would not move the pose along it either.
    """
    g00, g01, g02, g11, g12, g22 = with_fit_noise(info, variance, 1.0)
    dx = measured[0] - predicted[0]
    dy = measured[1] - predicted[1]
    dp = wrap_angle(measured[2] - predicted[2])
    return g00 * dx * dx + g11 * dy * dy + g22 * dp * dp + 2.0 * (g01 * dx * dy + g02 * dx * dp + g12 * dy * dp)


def refutes(measured: Pose, rows: list[list[float]], predicted: Pose, variance: Sequence[float], limit: float) -> bool:
    """Whether the fit refutes the prediction beyond the view's own noise: :func:`refutation_statistic` > ``limit``.

    ``rows``: the fit's 3x3 information as nested lists (the fusion's own conversion of it).
    """
    (h00, h01, h02), (_, h11, h12), (_, _, h22) = rows
    return refutation_statistic(measured, (h00, h01, h02, h11, h12, h22), predicted, variance) > limit
