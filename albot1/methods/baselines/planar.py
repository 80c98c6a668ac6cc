"""Single-pose SE(2) maths for the per-scan path of the baselines, and the
SE(2) <-> 4x4 SE(3) bridge to 3D registration libraries.

:mod:`albot1.geometry.se2` is vectorised over arrays of poses; on one pose
its broadcasting costs tens of microseconds per call, which matters inside a
mapper's timed ``process`` (a budget of ~1 ms per scan). These scalar forms
compute the same thing (a unit test checks it against ``se2``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def pose_matrix(pose: FloatArray) -> FloatArray:
    """SE(2) ``(x, y, theta)`` as the 4x4 homogeneous SE(3) matrix KISS-ICP works with."""
    x, y, theta = (float(v) for v in pose)
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0.0, x], [s, c, 0.0, y], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def planar_pose(matrix: FloatArray) -> tuple[FloatArray, float]:
    """Project a 4x4 pose to SE(2); also return the out-of-plane part dropped.

    The dropped part is ``max(|z| in m, tilt of the z axis in rad)``: zero
    for an exactly planar pose.
    """
    yaw = math.atan2(matrix[1, 0], matrix[0, 0])
    tilt = math.acos(min(1.0, max(-1.0, float(matrix[2, 2]))))
    return np.array([matrix[0, 3], matrix[1, 3], yaw]), max(abs(float(matrix[2, 3])), tilt)


def compose(a: FloatArray, b: FloatArray) -> FloatArray:
    """``a * b`` for single SE(2) poses (scalar maths: the per-scan path calls this a few times)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return np.array([a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], math.remainder(a[2] + b[2], math.tau)])


def between(a: FloatArray, b: FloatArray) -> FloatArray:
    """``inv(a) * b`` for single SE(2) poses."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return np.array([c * dx + s * dy, -s * dx + c * dy, math.remainder(b[2] - a[2], math.tau)])
