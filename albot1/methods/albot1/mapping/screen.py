"""Albot1+'s degeneracy screen: keep the odometry along the directions a view's fit does not fix (issue 21).

Why its own module: the screen is one idea (Zhang, Kaess and Singh's degeneracy-aware estimation, with a
chi-square gate on the directions kept), used by :class:`~albot1.methods.albot1.mapping.plus.PlusLocaliser`
when ``degenerate_sd`` or ``gate_probability`` is set (``docs/albot1-mapper.md``, "Where Albot1+ loses to
its odometry, and the degeneracy screen"); the linear algebra is the kernel
:func:`~albot1.methods.albot1.mapping.screen_kernels.screen_directions`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from albot1.geometry.se2 import Pose
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.mapping.screen_kernels import screen_directions


class ScreenParams(Protocol):
    """The settings the screen reads (``plus.PlusParams`` has them; a Protocol keeps this module below ``plus``)."""

    @property
    def degenerate_sd(self) -> float: ...  # fit sd (m, turns at m_per_rad) beyond which a direction is left
    @property
    def gate_probability(self) -> float: ...  # chi-square quantile of the gate; 0 = off
    @property
    def m_per_rad(self) -> float: ...  # metres a turn of 1 rad counts as


#: The signature of :func:`~albot1.methods.albot1.mapping.screen_kernels.screen_directions`.
ScreenDirections = Callable[
    [float, float, float, FloatArray, float, float, float, float, float],
    tuple[FloatArray, FloatArray, FloatArray, float, float, float, FloatArray],
]


@dataclass(frozen=True, slots=True)
class Screened:
    """A view's measured pose after :func:`screen_measurement`."""

    pose: Pose  # the odometry's component kept along the degenerate directions
    info: FloatArray  # 3x3, zero along the degenerate directions
    degenerate: bool  # at least one direction was left to the odometry
    rejected: bool  # the disagreement with the odometry exceeds the gate: use the prediction
    kept: int = 0  # directions the fit fixes
    mahalanobis: float = 0.0  # squared disagreement with the prediction along them (computed when the gate is on)


def screen_measurement(
    measured: Pose,
    info: FloatArray,
    predicted: Pose,
    prior_variance: tuple[float, float],
    params: ScreenParams,
    directions: ScreenDirections = screen_directions,
) -> Screened:
    """Degeneracy-aware use of a view's pose fit (after Zhang, Kaess and Singh, ICRA 2016).

    The fit's information matrix ``info`` (``J^T W J`` of its residuals, 3x3,
    position in m, heading in rad) is decomposed in units where a turn of
    1 rad counts ``m_per_rad`` metres. Along an eigenvector whose eigenvalue
    is below ``1 / degenerate_sd^2`` the landmarks and the scan do not fix
    the pose (a corridor whose lines are all parallel: its axis); there the
    measured pose is replaced by the odometry's prediction and the
    information is dropped, so the fusion keeps the odometry's component
    exactly, however a damped solver left that direction. Along the other
    directions the disagreement with the prediction is tested against the
    sum of the two stated covariances (the fit's inverse information and the
    odometry's ``prior_variance``, m^2 per axis and rad^2): beyond the
    ``gate_probability`` quantile of chi-square with as many degrees of
    freedom as directions kept, the fit is taken for a wrong association and
    rejected (the odometry's prediction is used). With no direction kept the
    view says nothing and the prediction is the pose. ``directions``: the
    kernel doing the linear algebra (:func:`~albot1.methods.albot1.mapping.screen_kernels.screen_directions`,
    compiled or as written).
    """
    floor = 1.0 / params.degenerate_sd**2 if params.degenerate_sd > 0.0 else 0.0
    eigval, basis, z, x, y, phi, info_kept = directions(
        measured[0],
        measured[1],
        measured[2],
        np.ascontiguousarray(info, dtype=float),
        predicted[0],
        predicted[1],
        predicted[2],
        params.m_per_rad,
        floor,
    )
    kept_n = basis.shape[1]
    degenerate = kept_n < 3
    if kept_n == 0:
        return Screened(predicted, np.zeros((3, 3)), degenerate, False)
    mahalanobis = 0.0
    if params.gate_probability > 0.0:
        # scipy's import (and the test) only when the gate is on: the statement costs ~0.1 ms a call.
        from scipy.stats import chi2  # noqa: PLC0415

        basis = np.ascontiguousarray(basis)  # numpy's own layout of eigvec[:, keep], so its products round as before
        prior_u = np.diag([prior_variance[0], prior_variance[0], prior_variance[1] * params.m_per_rad**2])
        cov = np.diag(1.0 / eigval[eigval > max(floor, 0.0)]) + basis.T @ prior_u @ basis
        mahalanobis = float(z @ np.linalg.solve(cov, z))
        if mahalanobis > float(chi2.ppf(params.gate_probability, kept_n)):
            return Screened(predicted, np.zeros((3, 3)), degenerate, True, kept_n, mahalanobis)
    return Screened((x, y, phi), info_kept, degenerate, False, kept_n, mahalanobis)
