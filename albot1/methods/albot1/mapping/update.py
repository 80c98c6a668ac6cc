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

from albot1.methods.albot1.mapping.accel import MappingKernels, mapping_kernels
from albot1.methods.albot1.mapping.perceptual_map import PerceptualMap

FloatArray = NDArray[np.float64]
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
    k = kernels or mapping_kernels()
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
            for row in np.flatnonzero(inside_count == 1).tolist():
                sid = int(cand[row])
                _extend_or_trim(
                    pmap,
                    sid,
                    segs[row],
                    bool(near[row, 0]),
                    view_map,
                    view_ids,
                    poly,
                    scan,
                    params,
                    k,
                    deleted,
                    extended,
                    trimmed,
                )
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


def _extend_or_trim(
    pmap: PerceptualMap,
    sid: int,
    seg: FloatArray,
    p1_inside: bool,
    view_map: FloatArray,
    view_ids: IntArray,
    poly: FloatArray,
    scan: int,
    params: UpdateParams,
    k: MappingKernels,
    deleted: list[int],
    extended: list[int],
    trimmed: list[int],
) -> None:
    """Lines 11-12: a map surface with one end inside the view.

    The corresponding view surface is the closest one (segment distance)
    that is parallel (either direction) within the angle and near within
    the distance, and not already taken by another map surface (note 17).
    The surface then runs from its outside end to the far end of that view
    surface (seen from the outside end): longer is "extended", shorter
    "trimmed" (Figure 3.13's S_e and S_r). With no corresponding surface it
    is clipped where it enters the grown polygon, or kept whole.
    """
    out_xy = seg[2:] if p1_inside else seg[:2]
    best = int(k.best_correspondence(seg, view_map, view_ids >= 0, params.correspond_angle, params.correspond_distance))
    old_len = math.hypot(seg[2] - seg[0], seg[3] - seg[1])
    if best >= 0:
        v = view_map[best]
        d1 = math.hypot(v[0] - out_xy[0], v[1] - out_xy[1])
        d2 = math.hypot(v[2] - out_xy[0], v[3] - out_xy[1])
        far = v[:2] if d1 >= d2 else v[2:]
        new = np.concatenate([far, out_xy]) if p1_inside else np.concatenate([out_xy, far])
        view_ids[best] = sid
    elif params.partial_without_match == "clip":
        in_xy = seg[:2] if p1_inside else seg[2:]
        t = float(
            k.clip_parameter(
                poly,
                view_map,
                float(out_xy[0]),
                float(out_xy[1]),
                float(in_xy[0]),
                float(in_xy[1]),
                params.delete_margin,
                params.margin_from == "surfaces",
            )
        )
        cut = out_xy + t * (in_xy - out_xy)
        new = np.concatenate([cut, out_xy]) if p1_inside else np.concatenate([out_xy, cut])
    else:
        return
    new_len = math.hypot(new[2] - new[0], new[3] - new[1])
    if new_len <= 1e-9:
        pmap.delete(sid, scan)
        deleted.append(sid)
        return
    if new_len > old_len:
        pmap.replace(sid, new, scan, "extended")
        extended.append(sid)
    else:
        pmap.replace(sid, new, scan, "trimmed")
        trimmed.append(sid)
