"""The thesis frame and its link to ROS REP-103.

The thesis describes every view with the robot at the origin facing +y and
surfaces ordered left to right (clockwise). A REP-103 point (x forward,
y left) is ``(-y, x)`` there; a beam at angle ``a`` (counter-clockwise from
forward) with range ``r`` lands at ``x = -r sin(a), y = r cos(a)``. This is a
rotation by +90 degrees, so headings and counter-clockwise angles are the same
number in both frames and a thesis pose ``(x, y, phi)`` maps to the REP-103
pose ``(y, -x, phi)``. The first view's frame is the map frame.

Poses here are plain float triples ``(x, y, phi)`` (view -> map:
``p_map = R(phi) p + (x, y)``): the mapper composes one or two per scan and
numpy's per-call overhead would dominate.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.methods.albot1.perception.kernels import wrap_angle

FloatArray = NDArray[np.float64]
Pose = tuple[float, float, float]


#: ``angle`` wrapped to ``[-pi, pi)`` (the kernels' scalar wrap, so both agree bit for bit).
wrap = wrap_angle


def compose(a: Pose, b: Pose) -> Pose:
    """``a * b``: pose ``b`` (given in ``a``'s frame) in ``a``'s parent frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap(a[2] + b[2]))


def between(a: Pose, b: Pose) -> Pose:
    """``inv(a) * b``: the pose of ``b`` seen from ``a`` (e.g. an odometry increment)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return (c * dx + s * dy, -s * dx + c * dy, wrap(b[2] - a[2]))


def rep_to_thesis_pose(pose: FloatArray | Pose) -> Pose:
    """REP-103 ``(x, y, theta)`` -> thesis ``(-y, x, theta)``."""
    return (-float(pose[1]), float(pose[0]), float(pose[2]))


def thesis_to_rep_pose(pose: Pose) -> Pose:
    """Thesis ``(x, y, phi)`` -> REP-103 ``(y, -x, phi)``."""
    return (pose[1], -pose[0], pose[2])


def thesis_to_rep_segments(segments: FloatArray) -> FloatArray:
    """Segments ``(m, 4)`` from the thesis frame to REP-103."""
    s = np.asarray(segments, dtype=float).reshape(-1, 4)
    return np.column_stack([s[:, 1], -s[:, 0], s[:, 3], -s[:, 2]])


def transform_segments(pose: Pose, segments: FloatArray) -> FloatArray:
    """Segments ``(m, 4)`` from a view into its parent frame with ``pose``."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    seg = np.asarray(segments, dtype=float).reshape(-1, 4)
    out = np.empty_like(seg)
    out[:, 0] = pose[0] + c * seg[:, 0] - s * seg[:, 1]
    out[:, 1] = pose[1] + s * seg[:, 0] + c * seg[:, 1]
    out[:, 2] = pose[0] + c * seg[:, 2] - s * seg[:, 3]
    out[:, 3] = pose[1] + s * seg[:, 2] + c * seg[:, 3]
    return out
