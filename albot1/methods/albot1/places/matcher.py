"""Recognising a place re-visited (thesis 4.1.2, Algorithm 6): the trigger and the structural match.

The trigger: "whenever Albot1 updates its map with the incoming view and
finds there are more than n co-locating surfaces in the map, it will attempt
to confirm if it is in a familiar place. n is a function of the size of the
place being re-visited; a smaller place requires a lesser number of surfaces."
Co-locating surfaces are the map surfaces an update deletes, extends or
trims (those the view covers), counted per remembered place through the
place each was marked with. We take the size of a place as its number of
structural surfaces (longer than 40 cm): ``n = max(trigger_min,
ceil(trigger_fraction * size))``.

The confirmation compares "the structural description of the current place
with the remembered place": the current place's surfaces (map frame) and
the remembered place's (its own frame), only those longer than 40 cm, the
``max_surfaces`` longest of each, longest first (long surfaces make the
steadiest hypotheses, and the first confirming hypothesis ends the search).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import Pose
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.places.config import MatchParams
from albot1.methods.albot1.places.kernels import PlacesKernels

#: At most this many of a place's longest surfaces are merged into its structure (bounds the cost).
_MERGE_AT_MOST = 1000


def trigger_threshold(size: int, params: MatchParams) -> int:
    """n of 4.1.2 for a remembered place with ``size`` structural surfaces: more than n co-locating triggers."""
    return max(params.trigger_min, math.ceil(params.trigger_fraction * size))


def structural(surfaces: FloatArray, params: MatchParams, kernels: PlacesKernels) -> FloatArray:
    """A place's structure: its surfaces merged where collinear, the longer than the minimum, longest first, capped.

    Merging (:func:`albot1.methods.albot1.places.kernels.merge_collinear`):
    the perceptual map holds a wall as several pieces (cut where furniture
    hid it, re-added a little apart by later views); counted piece by piece,
    two walls alone would make "more than 4" matches in any two rooms.
    """
    s = np.asarray(surfaces, dtype=float).reshape(-1, 4)
    if len(s) > _MERGE_AT_MOST:  # a visit of thousands of surfaces (a long corridor): its longest make the structure
        length = np.hypot(s[:, 2] - s[:, 0], s[:, 3] - s[:, 1])
        s = s[np.sort(np.argsort(-length, kind="stable")[:_MERGE_AT_MOST])]
    s = np.ascontiguousarray(s)
    s = kernels.merge_collinear(s, params.angle, 0.5 * params.gap, params.gap) if len(s) > 1 else s
    length = np.hypot(s[:, 2] - s[:, 0], s[:, 3] - s[:, 1])
    keep = np.flatnonzero(length > params.min_surface)
    order = keep[np.argsort(-length[keep], kind="stable")]
    return np.ascontiguousarray(s[order[: params.max_surfaces]])


def robot_sides(surfaces: FloatArray, pose: Pose) -> NDArray[np.int64]:
    """Which side of the robot (thesis frame: facing +y at ``pose``) each surface's midpoint is on: -1 left, +1 right.

    Left is counter-clockwise from the heading; a midpoint exactly on the heading line is 0.
    """
    mid_x = 0.5 * (surfaces[:, 0] + surfaces[:, 2]) - pose[0]
    mid_y = 0.5 * (surfaces[:, 1] + surfaces[:, 3]) - pose[1]
    c, s = math.cos(pose[2]), math.sin(pose[2])
    lateral = c * mid_x + s * mid_y  # x in the robot's thesis frame: negative = left
    return np.sign(lateral).astype(np.int64)


def centre(surfaces: FloatArray) -> FloatArray:
    """The centre of the bounding box of ``surfaces`` (the point whose displacement the shift gate measures)."""
    pts = np.asarray(surfaces, dtype=float).reshape(-1, 2)
    return np.ascontiguousarray(0.5 * (pts.min(axis=0) + pts.max(axis=0))) if len(pts) else np.zeros(2)


@dataclass(frozen=True, slots=True)
class Match:
    """The outcome of one confirmation: whether it confirmed, the best count, and the remembered place's frame."""

    confirmed: bool
    matches: int
    place_in_map: Pose


def confirm(
    current_map: FloatArray,
    remembered_own: FloatArray,
    pose: Pose,
    view_polygons: list[FloatArray],
    prior: Pose,
    params: MatchParams,
    kernels: PlacesKernels,
) -> Match:
    """Algorithm 6 on already selected surfaces (:func:`structural`); ``pose`` is the robot's, thesis frame.

    ``view_polygons`` are the polygons (Algorithm 3 line 7) of the current place's views in the map: the
    space they saw empty. ``prior`` is where the perceptual map put the remembered place's frame: a
    hypothesis turns it by at most ``params.max_turn`` and moves its centre by at most ``params.max_shift``.
    """
    if len(current_map) == 0 or len(remembered_own) == 0:
        return Match(False, 0, (0.0, 0.0, 0.0))
    found, count, theta, tx, ty = kernels.match_structure(
        current_map,
        robot_sides(current_map, pose),
        remembered_own,
        params.angle,
        params.gap,
        params.min_matches,
        params.anchors,
        np.ascontiguousarray(np.concatenate(view_polygons) if view_polygons else np.empty((0, 2))),
        np.cumsum([0] + [len(p) for p in view_polygons]).astype(np.int64),
        params.max_conflicts,
        np.asarray(prior, dtype=float),
        centre(remembered_own),
        params.max_turn,
        params.max_shift,
    )
    return Match(bool(found), int(count), (float(tx), float(ty), float(theta)))
