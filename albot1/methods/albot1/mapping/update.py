"""Updating the perceptual map with a view (thesis 3.1.7, Algorithm 3).

The view, already placed in the map, defines a polygon; map surfaces inside
it (or within 40 cm of its boundary) are deleted because the fresh view
describes that space better; a surface with one end inside and one outside
is extended or trimmed onto the view surface that corresponds to it
(Figures 3.12-3.13) and that view surface is not added again; every other
view surface is added.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.albot1.mapping.kernels import MappingKernels, polygon_points
from albot1.methods.albot1.mapping.perceptual_map import PerceptualMap

IntArray = NDArray[np.int64]


@dataclass(frozen=True, slots=True)
class UpdateParams:
    """Thresholds of Algorithm 3 (metres, radians); see :class:`albot1.methods.albot1.mapping.config.Albot1Config`."""

    delete_margin: float = 0.4
    correspond_angle: float = math.radians(5.0)
    correspond_distance: float = 0.4
    partial_without_match: Literal["clip", "keep"] = "clip"
    polygon: Literal["robot_and_endpoints", "endpoints"] = "robot_and_endpoints"
    margin_from: Literal["surfaces", "boundary"] = "surfaces"


@dataclass(frozen=True, slots=True)
class UpdateOutcome:
    """Which map id now holds each view surface, and what the update did."""

    view_ids: IntArray
    deleted: IntArray
    extended: IntArray
    trimmed: IntArray
    added: IntArray


def view_polygon(view_map: FloatArray, robot_xy: tuple[float, float], polygon: str) -> FloatArray:
    """Algorithm 3 line 7: the robot, then every surface's P1 and P2 left to right (note 15).

    The endpoints are in beam order around the robot, so the polygon is
    star-shaped about it (never self-intersecting) for fields of view under
    360 degrees; without the robot vertex the space between the robot and
    the view would never be cleared.
    """
    view = np.ascontiguousarray(view_map, dtype=float).reshape(-1, 4)
    return polygon_points(view, float(robot_xy[0]), float(robot_xy[1]), polygon == "robot_and_endpoints")


def update_map(
    pmap: PerceptualMap,
    view_map: FloatArray,
    robot_xy: tuple[float, float],
    scan: int,
    params: UpdateParams,
    kernels: MappingKernels | None = None,
) -> UpdateOutcome:
    """``updatePM`` for a view already transformed into the map (``view_map``, left to right).

    Lines 1-6 (placing the view with the reference landmark) are the
    caller's: that is the localisation pose applied to every surface. The
    rest is one compiled call on the map's arrays
    (:func:`~albot1.methods.albot1.mapping.kernels.update_surfaces`): the
    box query, the classification of the candidates' endpoints, the
    deletions, extensions and trims (lines 8-12) and the additions (line 13).
    """
    k = kernels or MappingKernels()
    view_map = np.ascontiguousarray(view_map, dtype=float).reshape(-1, 4)
    m = view_map.shape[0]
    pmap.reserve(m, pmap.live)
    view_ids, deleted, extended, trimmed, added, pmap.n, pmap.live, pmap.n_events = k.update_surfaces(
        pmap.seg,
        pmap.alive,
        pmap.added_at,
        pmap.slot_of,
        pmap.live_id,
        pmap.live_box,
        pmap.events,
        pmap.n,
        pmap.live,
        pmap.n_events,
        view_map,
        float(robot_xy[0]),
        float(robot_xy[1]),
        params.polygon == "robot_and_endpoints",
        scan,
        params.delete_margin,
        params.correspond_angle,
        params.correspond_distance,
        params.partial_without_match == "clip",
        params.margin_from == "surfaces",
    )
    return UpdateOutcome(view_ids, deleted, extended, trimmed, added)
