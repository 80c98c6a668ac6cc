"""Landmark recognition (thesis 3.1.5, Algorithm 1, eqs 3.1-3.4).

The robot's displacement between two views predicts where the previous
view's landmarks appear in the current one; a previous and a current landmark
are the same when their directions differ by less than 5 degrees and a
same-side stable endpoint moved less than 40 cm. The recognised current
landmark inherits the previous one's id (the id of its map surface).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import Pose, PoseLike
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.perception.kernels import PerceptionKernels

IntArray = NDArray[np.int64]

MotionModel = Literal["thesis", "exact"]
Matching = Literal["greedy", "nested_loop"]


def thesis_motion(d: float, theta: float) -> Pose:
    """Eqs 3.1-3.2: the current robot position in the previous view from distance and turn.

    ``x_R = d sin(-theta)``, ``y_R = d cos(-theta)``: the robot is placed ``d``
    along its *new* heading, exact for turn-then-drive steps only.
    """
    return (d * math.sin(-theta), d * math.cos(-theta), theta)


def motion_step(step_rep: PoseLike, model: MotionModel) -> Pose:
    """The current view's pose in the previous view's thesis frame, from a REP-103 odometry increment.

    ``"thesis"`` keeps only ``d = |(dx, dy)|`` and ``theta = dtheta`` (eqs
    3.1-3.2, what Algorithm 4 step 10 saves); ``"exact"`` uses the full
    increment, ``(-dy, dx, dtheta)`` in the thesis frame.
    """
    dx, dy, dth = float(step_rep[0]), float(step_rep[1]), float(step_rep[2])
    if model == "thesis":
        return thesis_motion(math.hypot(dx, dy), dth)
    return (-dy, dx, dth)


@dataclass(frozen=True, slots=True)
class Tracked:
    """A recognised-landmark list RL: surfaces of one view (its own frame) with their map ids.

    For landmarks recognised from a previous view, ``side`` (0 = P1, 1 = P2),
    ``gap`` (m) and ``angle_diff`` (rad) describe the match and
    ``prev_distance`` is the distance of the matched previous endpoint from
    the robot in the previous view (``d_R`` of eq. 3.5); they are NaN/-1
    for a list reset from a view's own landmarks.
    """

    surfaces: FloatArray
    kinds: IntArray
    ids: IntArray
    side: IntArray
    gap: FloatArray
    angle_diff: FloatArray
    prev_distance: FloatArray
    prev_distance_current: FloatArray

    def __len__(self) -> int:
        return int(self.ids.shape[0])

    @classmethod
    def fresh(cls, surfaces: FloatArray, kinds: IntArray, ids: IntArray) -> Tracked:
        n = int(len(ids))
        nan = np.full(n, np.nan)
        return cls(surfaces, kinds, np.asarray(ids, dtype=np.int64), np.full(n, -1, dtype=np.int64), nan, nan, nan, nan)


def recognise(
    previous: Tracked,
    surfaces: FloatArray,
    kinds: IntArray,
    step: Pose,
    *,
    max_angle: float,
    max_distance: float,
    matching: Matching = "greedy",
    kernels: PerceptionKernels | None = None,
) -> Tracked:
    """``recognizeLandmark``: the current landmarks (``surfaces``, ``kinds``) matched to ``previous``.

    ``matching="greedy"`` pairs one-to-one by smallest endpoint gap (the
    literal nested loop lets one surface match several); ``"nested_loop"``
    follows Algorithm 1 line by line: every passing pair writes the previous
    id onto the current surface (the last pair wins) and each current
    surface is saved once.
    """
    k = kernels or PerceptionKernels()
    if len(previous) == 0 or len(surfaces) == 0:
        return Tracked.fresh(np.empty((0, 4)), np.empty((0, 2), dtype=np.int64), np.empty(0, dtype=np.int64))
    i, j, side, gap, angle_diff, d_prev, d_prev_cur = k.recognise_landmarks(
        previous.surfaces,
        previous.kinds,
        surfaces,
        kinds,
        step[0],
        step[1],
        step[2],
        max_angle,
        max_distance,
        matching == "greedy",
    )
    # ``take`` rather than fancy indexing for the 2-D rows: the same rows, a third of the cost here (issue 24)
    return Tracked(
        surfaces.take(j, axis=0), kinds.take(j, axis=0), previous.ids[i], side, gap, angle_diff, d_prev, d_prev_cur
    )
