"""May the velocity guess's match move a node along a corridor its odometry match already explained? (Issue 21.)

The tracker starts ICP from the odometry guess and, where the last tracked
motion disagrees with it, from that constant-velocity guess too; the better
fit wins (:meth:`~albot1.methods.baselines.gtsam_graph.frontend.FrontEnd.follow`).
:mod:`.gating` already forbids the velocity match to overrule a passing
odometry match by a turn the tracker would not allow; nothing bounds its
translation. On logs that keep one scan per 2-3 m (orebro and acapulco
corrected) the constant-velocity guess lies a metre or more along the
corridor from the odometry guess, ICP converges there as well, and the
match that explains a few more points wins: with perfect odometry every
sequential slide of orebro (0.61, 1.67 and 1.03 m at scans 28, 133 and 135,
each stating sigmas of 2-4 cm) is such a velocity match winning over a
passing odometry match by inlier fractions 0.620 vs 0.614, 0.727 vs 0.673 and
0.764 vs 0.694 (docs/baselines.md, gtsam-graph, "sequential slides").

Two rules (the preset has the first on, the second off; measured in docs/baselines.md):

* the translation gate (``track_velocity_max_shift``): the velocity match
  must also lie within the tracker's translation gate of the odometry guess
  (the gate every match from that guess already obeys), the translation
  twin of :func:`.gating.velocity_match_allowed`;
* the scene test (``track_velocity_distinct_ratio``): the scan is scored at
  both matched poses against the local map, a mean of ``exp(-d^2 / 2
  sigma^2)`` over its points (``d`` the distance to the nearest map point,
  ``sigma`` the match's point noise); when the odometry match's score is more
  than ``ratio`` of the velocity match's, the map does not tell the two
  poses apart (a corridor along their difference), so the odometry match,
  whose guess did not need the slide, stands.
"""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph.registration import Target


def shift_m(pose: FloatArray, odometry_guess: FloatArray) -> float:
    """How far ``pose`` lies from ``odometry_guess`` (both in the same frame), in metres."""
    step = se2.between(odometry_guess, pose)
    return math.hypot(float(step[0]), float(step[1]))


def alignment_score(target: Target, points: FloatArray, pose: FloatArray, sigma_m: float) -> float:
    """The mean of ``exp(-d^2 / 2 sigma_m^2)`` over ``points`` moved by ``pose``; ``d`` is the nearest target point.

    1 when every point lies on a map point, 0 for an empty scan or map.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    if target.tree is None or len(pts) == 0:
        return 0.0
    moved = se2.transform_points(pose, pts)
    dist, _ = target.tree.query(moved)
    return float(np.mean(np.exp(-0.5 * (np.asarray(dist) / sigma_m) ** 2)))


def slide_refused(
    target: Target,
    points: FloatArray,
    velocity_pose: FloatArray,
    odometry_pose: FloatArray,
    odometry_guess: FloatArray,
    max_shift_m: float | None,
    distinct_ratio: float,
    sigma_m: float,
) -> str:
    """``""`` when the velocity match may replace the passing odometry match, else why not.

    ``max_shift_m`` None leaves the translation gate off; ``distinct_ratio``
    0 the scene test (module docstring).
    """
    if max_shift_m is not None:
        shift = shift_m(velocity_pose, odometry_guess)
        if shift > max_shift_m:
            return f"shift {shift:.2f} m > {max_shift_m:.2f} m"
    if distinct_ratio > 0:
        velocity_score = alignment_score(target, points, velocity_pose, sigma_m)
        odometry_score = alignment_score(target, points, odometry_pose, sigma_m)
        if odometry_score > distinct_ratio * velocity_score:
            return f"indistinct ({odometry_score:.3f} vs {velocity_score:.3f})"
    return ""
