"""Locating Albot1 in its perceptual map (thesis 3.1.6, Algorithm 2, eqs 3.5-3.7).

Each recognised landmark gives one candidate robot pose: the landmark as
seen now is laid onto its position in the map (eqs 3.6-3.7 on the robot's
two points of Algorithm 2). Candidates far from the others are dropped by
the standard-deviation rule, the rest are ranked by goodness (eq. 3.5) and
the best one is the robot's pose.

Eqs 3.6-3.7 rotate the map surface's unit direction by the angle between the
view surface and the reference-point-to-robot line, and walk the
reference-point-to-robot distance from the map's reference point: that is
the rigid motion aligning the view landmark's reference point and direction
with the map's, so :func:`landmark_pose` computes that motion in closed form
and :func:`algorithm2_pose` (the literal two-point construction) is kept to
prove the equivalence in the tests. Eqs 3.6-3.7 use P1 as reference point
(the thesis's worked case); here the reference is the endpoint the recognition
matched (the one eq. 3.5's gap and distance measure) when it is stable in the
map record too, else the other end, P1 first for a list without match data
(note 11, docs/albot1-mapper.md item 16).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from itertools import compress

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import Pose, wrap_angle
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.perception.endpoints import STABLE
from albot1.methods.albot1.perception.recognition import Tracked

IntArray = NDArray[np.int64]

#: :data:`~albot1.methods.albot1.perception.endpoints.STABLE` as a Python list (the loop below runs on Python scalars).
STABLE_KINDS: list[bool] = STABLE.tolist()

#: Algorithm 2 step 2: the robot as a surface from (0, 0) to (0, 50 cm) in its own view.
ROBOT_AHEAD_M = 0.5


def eq_3_6_3_7(x1: float, y1: float, x2: float, y2: float, d_p: float, theta: float) -> tuple[float, float]:
    """Eqs 3.6-3.7 verbatim: a point at distance ``d_p`` and angle ``theta`` from the map surface's P1."""
    s_l = math.hypot(x2 - x1, y2 - y1)
    ux, uy = (x2 - x1) / s_l, (y2 - y1) / s_l
    return (
        x1 + d_p * (ux * math.cos(theta) - uy * math.sin(theta)),
        y1 + d_p * (ux * math.sin(theta) + uy * math.cos(theta)),
    )


def _reference(seg: FloatArray | Sequence[float], side: int) -> tuple[float, float]:
    return (float(seg[2 * side]), float(seg[2 * side + 1]))


def _direction(seg: FloatArray | Sequence[float]) -> float:
    return math.atan2(float(seg[3] - seg[1]), float(seg[2] - seg[0]))


def dp_theta(view_seg: FloatArray, side: int, point: tuple[float, float]) -> tuple[float, float]:
    """Figure 3.10a: distance from the reference point to ``point`` and its angle from the surface direction."""
    rx, ry = _reference(view_seg, side)
    dx, dy = point[0] - rx, point[1] - ry
    return math.hypot(dx, dy), wrap_angle(math.atan2(dy, dx) - _direction(view_seg))


def algorithm2_pose(map_seg: FloatArray, view_seg: FloatArray, side: int) -> Pose:
    """Algorithm 2 literally: the robot points (0, 0) and (0, 50 cm) placed with eqs 3.6-3.7.

    The pose heading is that of P1->P2 minus 90 degrees, because the robot
    faces +y in its own view.
    """
    mx1, my1, mx2, my2 = (float(v) for v in map_seg)
    if side == 1:
        # Anchored at P2: same direction, origin moved to the map's P2.
        ax, ay = mx2, my2
        mx1, my1, mx2, my2 = ax, ay, ax + (mx2 - mx1), ay + (my2 - my1)
    p = []
    for point in ((0.0, 0.0), (0.0, ROBOT_AHEAD_M)):
        d_p, theta = dp_theta(view_seg, side, point)
        p.append(eq_3_6_3_7(mx1, my1, mx2, my2, d_p, theta))
    heading = math.atan2(p[1][1] - p[0][1], p[1][0] - p[0][0]) - math.pi / 2.0
    return (p[0][0], p[0][1], wrap_angle(heading))


def landmark_pose(map_seg: FloatArray | Sequence[float], view_seg: FloatArray | Sequence[float], side: int) -> Pose:
    """The view's pose in the map that lays ``view_seg`` onto ``map_seg`` at the reference point ``side``.

    :func:`_direction`, :func:`_reference` and ``rotate`` written out (the same operations in the same order):
    localisation calls this for every recognised landmark of every scan, where the calls cost more than the sums.
    """
    phi = wrap_angle(
        math.atan2(float(map_seg[3] - map_seg[1]), float(map_seg[2] - map_seg[0]))
        - math.atan2(float(view_seg[3] - view_seg[1]), float(view_seg[2] - view_seg[0]))
    )
    i = 2 * side
    vx, vy = float(view_seg[i]), float(view_seg[i + 1])
    c, s = math.cos(phi), math.sin(phi)
    return (float(map_seg[i]) - (c * vx - s * vy), float(map_seg[i + 1]) - (s * vx + c * vy), phi)


def outlier_keep(positions: Sequence[tuple[float, float]], min_candidates: int) -> list[bool]:
    """3.1.6's rule: drop candidates farther from the mean than the standard deviation.

    The standard deviation is the RMS distance from the mean (note 10); with
    fewer than ``min_candidates`` candidates nothing is dropped (with two,
    both sit exactly at one standard deviation).
    """
    n = len(positions)
    if n < min_candidates:
        return [True] * n
    # sums of lists, not of generators: the same additions in the same order, without a generator's cost
    mx = sum([p[0] for p in positions]) / n
    my = sum([p[1] for p in positions]) / n
    dist = [math.hypot(p[0] - mx, p[1] - my) for p in positions]
    sigma = math.sqrt(sum([d * d for d in dist]) / n)
    return [d <= sigma * (1.0 + 1e-12) for d in dist]


def goodness(length: float, d_r: float, g_diff: float, a_diff: float, gap_floor: float, angle_floor: float) -> float:
    """Eq. 3.5: ``S_L / (d_R * g_diff * a_diff)``, gap and angle floored (note 9); only the ranking matters."""
    return length / (max(d_r, 1e-9) * max(g_diff, gap_floor) * max(a_diff, angle_floor))


@dataclass(frozen=True, slots=True)
class Localisation:
    """The chosen pose, the landmark id it came from and every candidate (for traces and tests).

    The candidates are kept as the lists localisation built; their arrays are
    made on demand (the thesis path reads only the pose and its landmark).
    """

    pose: Pose
    reference_id: int
    ids: list[int]
    poses: list[Pose]
    keep: list[bool]
    scores: list[float]

    @property
    def candidate_ids(self) -> IntArray:
        """The landmark id of every candidate."""
        return np.asarray(self.ids, dtype=np.int64)

    @property
    def candidates(self) -> FloatArray:
        """Every candidate pose ``(c, 3)``."""
        return np.asarray(self.poses, dtype=float)

    @property
    def kept(self) -> NDArray[np.bool_]:
        """Which candidates the outlier rule kept."""
        return np.asarray(self.keep, dtype=bool)

    @property
    def goodness(self) -> FloatArray:
        """Each candidate's goodness (eq. 3.5)."""
        return np.asarray(self.scores, dtype=float)


def localise(
    tracked: Tracked,
    landmark_map: Mapping[int, tuple[FloatArray | Sequence[float], IntArray | Sequence[int]]],
    *,
    min_candidates: int,
    gap_floor: float,
    angle_floor: float,
    distance_view: str = "previous",
) -> Localisation | None:
    """``localize``: the robot pose from the best recognised landmark, or None if none is usable.

    ``landmark_map`` holds each landmark id's surface and endpoint labels as
    placed in the map at the update that introduced it (kept apart from the
    editable map surfaces, which later updates may extend or trim; note 12).
    A landmark is usable through an endpoint that is stable both now and in
    that record, the matched side first. A list freshly reset from a view
    has no match data (gap, angle, d_R): its landmarks rank by length alone.
    Runs on Python scalars: the thesis's steps as written, kept as the
    reference. The mapper runs the same steps compiled, for every preset
    (:func:`~.localise_kernels.robust_starts`, which adds Albot1+'s start
    poses; the tests hold the two to the same bits).
    """
    ids: list[int] = []
    poses: list[Pose] = []
    scores: list[float] = []
    kinds = tracked.kinds.tolist()
    sides = tracked.side.tolist()
    d_prev = (tracked.prev_distance if distance_view == "previous" else tracked.prev_distance_current).tolist()
    gaps = tracked.gap.tolist()
    adiffs = tracked.angle_diff.tolist()
    surfaces = tracked.surfaces.tolist()
    for k, sid in enumerate(tracked.ids.tolist()):
        record = landmark_map.get(sid)
        if record is None:
            continue
        map_seg, map_kinds = record
        matched = sides[k]
        side = -1
        for s in (matched, 1 - matched) if matched >= 0 else (0, 1):
            if STABLE_KINDS[kinds[k][s]] and STABLE_KINDS[map_kinds[s]]:
                side = s
                break
        if side < 0:
            continue
        seg = surfaces[k]
        ids.append(sid)
        poses.append(landmark_pose(map_seg, seg, side))
        length = math.hypot(seg[2] - seg[0], seg[3] - seg[1])
        # NaN (x != x) marks a list freshly reset from a view: no match data.
        d_r = d_prev[k] if d_prev[k] == d_prev[k] else 1.0
        g = gaps[k] if gaps[k] == gaps[k] else gap_floor
        a = adiffs[k] if adiffs[k] == adiffs[k] else angle_floor
        scores.append(goodness(length, d_r, g, a, gap_floor, angle_floor))
    if not poses:
        return None
    n = len(poses)
    kept = outlier_keep([(p[0], p[1]) for p in poses], min_candidates)
    best = max(compress(range(n), kept), key=scores.__getitem__)  # the first best-scored kept candidate
    return Localisation(poses[best], ids[best], ids, poses, kept, scores)
