"""The thesis frame and its link to ROS REP-103.

The thesis describes every view with the robot at the origin facing +y and
surfaces ordered left to right (clockwise). A REP-103 point (x forward,
y left) is ``(-y, x)`` there; a beam at angle ``a`` (counter-clockwise from
forward) with range ``r`` lands at ``x = -r sin(a), y = r cos(a)``. This is a
rotation by +90 degrees, so headings and counter-clockwise angles are the same
number in both frames and a thesis pose ``(x, y, phi)`` maps to the REP-103
pose ``(y, -x, phi)``. The first view's frame is the map frame.

Poses in the thesis frame are composed with the scalar API of
:mod:`albot1.geometry.se2` (plain float triples, view -> map:
``p_map = R(phi) p + (x, y)``): SE(2) does not care which way the robot
faces, only these conversions do.
"""

from __future__ import annotations

import numpy as np

from albot1.geometry.se2 import Pose, PoseLike
from albot1.geometry.types import FloatArray


def rep_to_thesis_pose(pose: PoseLike) -> Pose:
    """REP-103 ``(x, y, theta)`` -> thesis ``(-y, x, theta)``."""
    return (-float(pose[1]), float(pose[0]), float(pose[2]))


def thesis_to_rep_pose(pose: Pose) -> Pose:
    """Thesis ``(x, y, phi)`` -> REP-103 ``(y, -x, phi)``."""
    return (pose[1], -pose[0], pose[2])


def thesis_to_rep_segments(segments: FloatArray) -> FloatArray:
    """Segments ``(m, 4)`` from the thesis frame to REP-103."""
    s = np.asarray(segments, dtype=float).reshape(-1, 4)
    return np.column_stack([s[:, 1], -s[:, 0], s[:, 3], -s[:, 2]])
