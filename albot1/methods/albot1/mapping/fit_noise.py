"""Albot1+'s fit noise in the fusion: a view's fit weighs what its measured scatter allows, not what it states.

The pose fit's information matrix (``J^T W J`` of its landmark and scan terms) counts every scan point as an
independent measurement of the stated ``scan_sigma``. On fr-clinic it states a heading sigma of 0.08-0.12 deg in
views whose fit swings by 1-4 deg from one view to the next (``docs/albot1-mapper.md``, "Support and fit noise",
the seventh pass). The fusion with the odometry's prediction then keeps most of each departure, and the next map
update freezes it: on a log with good odometry the heading walks away from it by +-10 deg over the route.

The view noise (:mod:`.view_noise`) already measures that scatter: the running median of how far the fit strays
from a prediction it does not refute. :func:`with_fit_noise` adds it (times ``factor``) to the fit's stated
covariance before the combination, so the fit's information is that of ``stated covariance + factor * scatter``.
Where the odometry is good the fit no longer out-votes it on its stated sigma alone.

A view that refutes the prediction strongly (the ambiguity test's likelihood ratio far above its quantile) is
not a scatter of that size: there the odometry is off, and its correction must not be damped (mit-csail's turns,
whose odometry errs by several degrees, go above their odometry when every fit is damped alike). So the added
variance falls with the square of the ratio beyond ``statistic_scale`` (:func:`fit_noise_factor`): a view at
ten times that ratio gets 1 % of it.
"""

from __future__ import annotations

from collections.abc import Sequence

#: The fit's information as the fusion reads it: ``(h00, h01, h02, h11, h12, h22)`` (position m, heading rad).
Information = tuple[float, float, float, float, float, float]


def fit_noise_factor(factor: float, statistic: float, statistic_scale: float) -> float:
    """``factor * min(1, (statistic_scale / statistic)^2)``: the scatter's multiple added for a view of this ratio.

    ``statistic``: the view's likelihood ratio against the prediction (:func:`.ambiguity.view_ambiguity`);
    ``statistic_scale`` <= 0: no fall-off (``factor`` for every view).
    """
    if statistic_scale <= 0.0 or statistic <= statistic_scale:
        return factor
    ratio = statistic_scale / statistic
    return factor * ratio * ratio


def with_fit_noise(info: Information, variance: Sequence[float], factor: float) -> Information:
    """The information of ``info^-1 + factor * diag(v_xy, v_xy, v_phi)``; ``info`` itself when ``factor <= 0``.

    ``variance``: the view noise ``(m^2 per position axis, rad^2)``. Computed as ``(1 + I D)^-1 I``, which needs no
    inverse of ``I`` (a fit may leave a direction with no information: it stays without any) and whose matrix
    ``1 + I D`` is never singular for a positive semi-definite ``I``. Written out for 3x3 (numpy's per-call
    overhead would cost more than the arithmetic); the result is made exactly symmetric.
    """
    if factor <= 0.0:
        return info
    h00, h01, h02, h11, h12, h22 = info
    dx = factor * variance[0]
    dp = factor * variance[1]
    # A = 1 + I D (D = diag(dx, dx, dp)), row by row
    a00, a01, a02 = 1.0 + h00 * dx, h01 * dx, h02 * dp
    a10, a11, a12 = h01 * dx, 1.0 + h11 * dx, h12 * dp
    a20, a21, a22 = h02 * dx, h12 * dx, 1.0 + h22 * dp
    c00 = a11 * a22 - a12 * a21
    c01 = a02 * a21 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    c10 = a12 * a20 - a10 * a22
    c11 = a00 * a22 - a02 * a20
    c12 = a02 * a10 - a00 * a12
    c20 = a10 * a21 - a11 * a20
    c21 = a01 * a20 - a00 * a21
    c22 = a00 * a11 - a01 * a10
    det = a00 * c00 + a01 * c10 + a02 * c20
    # (A^-1 I): A^-1 = C / det with C the adjugate above (rows c0*, c1*, c2*)
    g00 = (c00 * h00 + c01 * h01 + c02 * h02) / det
    g01 = (c00 * h01 + c01 * h11 + c02 * h12) / det
    g02 = (c00 * h02 + c01 * h12 + c02 * h22) / det
    g10 = (c10 * h00 + c11 * h01 + c12 * h02) / det
    g11 = (c10 * h01 + c11 * h11 + c12 * h12) / det
    g12 = (c10 * h02 + c11 * h12 + c12 * h22) / det
    g20 = (c20 * h00 + c21 * h01 + c22 * h02) / det
    g21 = (c20 * h01 + c21 * h11 + c22 * h12) / det
    g22 = (c20 * h02 + c21 * h12 + c22 * h22) / det
    return (g00, 0.5 * (g01 + g10), 0.5 * (g02 + g20), g11, 0.5 * (g12 + g21), g22)
