"""A sequential match's covariance estimated from the match's own geometry (``match_covariance_shaped``, off).

Why: ICP's Gauss-Newton covariance (``inv(J' W J / point_sigma**2)``) is
smaller than the floor (on edmonton-corrected with perfect odometry 7 / 12 mm
along the strong / weak axis, median), because it treats every point-to-line
residual as independent, which points on one wall are not (they share the
wall's fitted line; Censi 2007). So every match states about the constant
floor (``match_sigma_floor_xy_m``, 0.02 m), isotropic, and the floor decides.
With perfect odometry on edmonton-corrected and infinite-corridor-corrected
the matches' real translation errors are 1.5-2.3x that floor in variance, and
largest along the match's weak axis (whitened RMS 1.6 weak / 0.9 strong:
docs/baselines.md, gtsam-graph, "where the error with perfect odometry comes
from"): the floor is about right where the scan constrains the match best and
too small along a corridor.

The estimate here keeps the information's *shape* and the floor's *scale*:
the translation information (the Schur complement of the heading, so a
lever-arm coupling does not count as translation knowledge) is scaled so
that its best-constrained axis carries exactly the floor's information
``1 / floor**2``; any weaker axis gets less in the ratio of its eigenvalue to
the largest, i.e. a variance of ``floor**2 * lambda_max / lambda``. The
odometry prior the match started from (``odometry_sigma_xy_m``) is added in
information, as in the floor's formula, so a fully degenerate axis (a bare
corridor) states the prior's variance rather than infinity. The heading keeps
the floor's formula (its claim holds: chi-square 0.56-0.68 per dof).

The covariance is that of additive (x, y, theta) errors with the translation
in the parent node's frame, as ICP's information and :mod:`.odometry_trust`'s
innovations are; :func:`.graph.body_frame_covariance` re-expresses it in GTSAM's
tangent frame when the edge joins the graph (with the floor's isotropic
translation that rotation changed nothing; with a shaped one it matters).
"""

from __future__ import annotations

import numpy as np

from albot1.geometry.types import FloatArray


def floor_covariance(information: FloatArray, prior: FloatArray, floor: FloatArray) -> FloatArray:
    """The match covariance used by default: ICP's own (with its start prior) plus the constant floor."""
    return np.asarray(np.linalg.inv(information + prior) + floor, dtype=np.float64)


def shaped_covariance(information: FloatArray, prior: FloatArray, floor: FloatArray) -> FloatArray:
    """The match covariance in the parent frame: translation shaped by ``information``, scaled by ``floor``.

    ``information`` is ICP's 3x3 (x, y, theta), ``prior`` the information of
    the guess it started from, ``floor`` the diagonal floor covariance. A
    match with no translation information at all states the prior's
    translation alone.
    """
    info = np.asarray(information, dtype=float)
    base = floor_covariance(info, prior, floor)
    if info[2, 2] > 0.0:
        translation = info[:2, :2] - np.outer(info[:2, 2], info[2, :2]) / info[2, 2]
    else:
        translation = info[:2, :2].copy()
    translation = 0.5 * (translation + translation.T)
    largest = float(np.linalg.eigvalsh(translation)[-1])
    if not np.isfinite(largest) or largest <= 0.0:
        scaled = np.zeros((2, 2))
    else:
        scaled = translation / (float(floor[0, 0]) * largest)
    # eigenvalues may dip a hair below 0 on a degenerate axis: the prior keeps the sum positive definite
    block = np.linalg.inv(scaled + np.asarray(prior, dtype=float)[:2, :2])
    out = np.zeros((3, 3))
    out[:2, :2] = 0.5 * (block + block.T)
    out[2, 2] = base[2, 2]
    return out
