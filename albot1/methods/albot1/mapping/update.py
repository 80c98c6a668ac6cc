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
from albot1.methods.albot1.mapping.kernels import DELETED, EXTENDED, TRIMMED, MappingKernels
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
    pts = view_map.reshape(-1, 2)
    if polygon == "robot_and_endpoints":
        pts = np.vstack([np.asarray(robot_xy, dtype=float).reshape(1, 2), pts])
    return np.ascontiguousarray(pts)


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
    caller's: that is the localisation pose applied to every surface.
    """
    k = kernels or MappingKernels()
    view_map = np.ascontiguousarray(view_map, dtype=float).reshape(-1, 4)
    m = view_map.shape[0]
    view_ids = np.full(m, -1, dtype=np.int64)
    deleted: list[int] = []
    extended: list[int] = []
    trimmed: list[int] = []
    if m:
        poly = view_polygon(view_map, robot_xy, params.polygon)
        lo = poly.min(axis=0) - params.delete_margin
        hi = poly.max(axis=0) + params.delete_margin
        cand = pmap.query(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
        if len(cand):
            segs = pmap.segments(cand)
            near = k.classify_endpoints(
                poly,
                view_map,
                np.ascontiguousarray(segs.reshape(-1, 2)),
                params.delete_margin,
                params.margin_from == "surfaces",
            )
            near = near.reshape(-1, 2)
            inside_count = near.sum(axis=1)
            for row in np.flatnonzero(inside_count == 2).tolist():
                sid = int(cand[row])
                pmap.delete(sid, scan)
                deleted.append(sid)
            partial = np.flatnonzero(inside_count == 1)
            if len(partial):
                action, new_segs, match = k.resolve_partial(
                    np.ascontiguousarray(segs[partial]),
                    np.ascontiguousarray(near[partial, 0]),
                    view_map,
                    view_ids >= 0,
                    poly,
                    params.correspond_angle,
                    params.correspond_distance,
                    params.partial_without_match == "clip",
                    params.delete_margin,
                    params.margin_from == "surfaces",
                )
                for r, (row, act, taken) in enumerate(zip(partial.tolist(), action.tolist(), match.tolist())):
                    sid = int(cand[row])
                    if taken >= 0:
                        view_ids[taken] = sid
                    if act == DELETED:
                        pmap.delete(sid, scan)
                        deleted.append(sid)
                    elif act == EXTENDED:
                        pmap.replace(sid, new_segs[r], scan, "extended")
                        extended.append(sid)
                    elif act == TRIMMED:
                        pmap.replace(sid, new_segs[r], scan, "trimmed")
                        trimmed.append(sid)
    fresh = np.flatnonzero(view_ids < 0)
    added = pmap.add(view_map[fresh], scan) if len(fresh) else np.empty(0, dtype=np.int64)
    view_ids[fresh] = added
    return UpdateOutcome(
        view_ids,
        np.asarray(deleted, dtype=np.int64),
        np.asarray(extended, dtype=np.int64),
        np.asarray(trimmed, dtype=np.int64),
        added,
    )
