"""Exits: doorway-like gaps detected in views, tracked into the perceptual map, and crossed.

Thesis 4.1.1 assumes "an office-like environment with well-defined exits
(i.e. doorway, a gap whose typical size is about 1 meter)" and computes a
place "whenever an exit is crossed", without saying how exits are found.
Our detector (:func:`albot1.methods.albot1.places.kernels.detect_exits`)
takes a gap between two surface ends of one view, both occluding (real
edges with something farther beside them), 0.6-1.2 m wide, with everything
seen through it lying beyond it: the view of a doorway from the room.

Each detection is placed in the map with the pose of its scan and joins the
tracked exit whose midpoint is within ``track_distance`` and whose direction
is within ``track_angle`` (the latest sighting replaces the segment: the map
drifts, the newest placement agrees best with the robot's current pose);
otherwise it starts a new track. A track seen in ``min_sightings`` views can
be crossed.

The crossing test has hysteresis: the robot is on a side of an exit only
when farther than ``crossing_band`` from its line; a crossing is a change of
side whose straight path (from where the old side was last confirmed to
here) passes between the exit's ends (with ``crossing_margin`` of slack).
Jitter on the line is therefore not a crossing, and neither is walking past
the end of a doorway's wall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import Pose
from albot1.geometry.segments import segments_cross, transform_segments
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.perception.view import View
from albot1.methods.albot1.places.config import ExitParams
from albot1.methods.albot1.places.kernels import PlacesKernels

IntArray = NDArray[np.int64]

#: How often (scans) unconfirmed tracks that have not been seen for ``_STALE_SCANS`` are dropped.
_PRUNE_EVERY = 200
_STALE_SCANS = 200


def view_exits(view: View, params: ExitParams, kernels: PlacesKernels) -> FloatArray:
    """Exits of one view ``(k, 4)`` in its own (thesis) frame, each from the left surface's end to the right one's."""
    if len(view) < 2:
        return np.empty((0, 4))
    i, j = kernels.detect_exits(
        view.surfaces,
        view.kinds,
        params.min_width,
        params.max_width,
        params.min_depth,
        params.max_distance,
        params.both_occluding,
    )
    if len(i) == 0:
        return np.empty((0, 4))
    s = view.surfaces
    return np.column_stack([s[i, 2], s[i, 3], s[j, 0], s[j, 1]])


@dataclass(frozen=True, slots=True)
class Crossing:
    """An exit crossed at ``scan``: ``segment`` (map frame) runs so that the side left behind is on its left."""

    track: int
    scan: int
    segment: FloatArray
    before: tuple[float, float]
    after: tuple[float, float]


def orient_left(segment: FloatArray, point: tuple[float, float]) -> FloatArray:
    """``segment`` reversed if needed so that ``point`` lies on its left (counter-clockwise side)."""
    a, b = segment[:2], segment[2:]
    side = (b[0] - a[0]) * (point[1] - a[1]) - (b[1] - a[1]) * (point[0] - a[0])
    return segment.copy() if side >= 0 else np.concatenate([b, a])


class ExitTracker:
    """Exits tracked in the map frame, with each one's side of the robot for the crossing test."""

    def __init__(self, params: ExitParams, kernels: PlacesKernels) -> None:
        self.params = params
        self._k = kernels
        self._seg = np.empty((0, 4))
        self._ids = np.empty(0, dtype=np.int64)
        self._sightings = np.empty(0, dtype=np.int64)
        self._last_seen = np.empty(0, dtype=np.int64)
        self._side = np.empty(0, dtype=np.int64)  # +1 left of the segment, -1 right, 0 not yet known
        self._side_at = np.empty((0, 2))  # where the robot last was clearly on that side
        self._mute = np.empty(0, dtype=np.int64)  # a twin of an exit just crossed: the side the robot heads for
        self._next_id = 0
        self._confirmed_seen = -(10**9)  # the last scan a crossable exit was seen (no recent one: nothing to test)
        self.detections = 0

    def __len__(self) -> int:
        return int(self._ids.shape[0])

    @property
    def confirmed(self) -> int:
        """How many tracked exits have been seen often enough to be crossed."""
        return int(np.count_nonzero(self._sightings >= self.params.min_sightings))

    def segments(self, confirmed_only: bool = True) -> FloatArray:
        """Tracked exits ``(k, 4)`` in the map frame."""
        keep = self._sightings >= self.params.min_sightings if confirmed_only else slice(None)
        return self._seg[keep].copy()

    def _recent(self, scan: int) -> NDArray[np.bool_]:
        """Crossable tracks seen in the last ``recent_scans``: placed consistently with the robot's current pose.

        Older tracks were placed in a map that has drifted since, and may lie a
        metre off: a doorway's old track can fall inside the room it leads to.
        """
        p = self.params
        return (self._sightings >= p.min_sightings) & (scan - self._last_seen <= p.recent_scans)

    def beyond(self, origin: tuple[float, float], points: FloatArray, scan: int) -> IntArray:
        """For each point ``(J, 2)``: the id of the recently seen exit the line from ``origin`` to it passes through.

        -1 where it passes through none. Such a point was seen *through* that
        exit: it belongs to the place beyond (the nearest exit along the line
        when it passes several).
        """
        if len(points) == 0 or scan - self._confirmed_seen > self.params.recent_scans:
            return np.full(len(points), -1, dtype=np.int64)
        return self._k.seen_through(
            self._seg,
            self._ids,
            self._recent(scan),
            float(origin[0]),
            float(origin[1]),
            np.ascontiguousarray(points, dtype=float).reshape(-1, 2),
        )

    def twins(self, track: int) -> list[int]:
        """Ids of the tracks within the twin distance of ``track`` (itself included): one doorway's placements."""
        row = np.flatnonzero(self._ids == track)
        if len(row) == 0:
            return [track]
        mids = 0.5 * (self._seg[:, :2] + self._seg[:, 2:])
        here = mids[row[0]]
        close = np.hypot(mids[:, 0] - here[0], mids[:, 1] - here[1]) <= self.params.twin_distance
        twins: list[int] = self._ids[close].tolist()
        return twins

    def near(self, position: tuple[float, float], distance: float, scan: int) -> bool:
        """Whether ``position`` is within ``distance`` of a recently seen exit (standing in a doorway)."""
        p = self.params
        if scan - self._confirmed_seen > p.recent_scans:
            return False
        return bool(
            self._k.near_exit(
                self._seg,
                self._sightings,
                self._last_seen,
                p.min_sightings,
                p.recent_scans,
                scan,
                float(position[0]),
                float(position[1]),
                distance,
            )
        )

    def observe(self, view: View, pose: Pose, scan: int) -> FloatArray:
        """Detect the exits of ``view`` (taken at ``pose``) and track them; returns them in the map frame."""
        if scan % _PRUNE_EVERY == 0:
            self._prune(scan)
        local = view_exits(view, self.params, self._k)
        if len(local) == 0:
            return local
        found = transform_segments(pose, local)
        for seg in found:
            self._track(seg, scan)
        self.detections += len(found)
        return found

    def _track(self, seg: FloatArray, scan: int) -> None:
        p = self.params
        mid = 0.5 * (seg[:2] + seg[2:])
        if len(self._ids):
            mids = 0.5 * (self._seg[:, :2] + self._seg[:, 2:])
            dist = np.hypot(mids[:, 0] - mid[0], mids[:, 1] - mid[1])
            r = int(np.argmin(dist))
            if dist[r] <= p.track_distance and _undirected_angle(self._seg[r], seg) <= p.track_angle:
                self._seg[r] = seg
                self._sightings[r] += 1
                self._last_seen[r] = scan
                if self._sightings[r] >= p.min_sightings:
                    self._confirmed_seen = scan
                return
        self._seg = np.vstack([self._seg, seg[None]])
        self._ids = np.append(self._ids, self._next_id)
        self._sightings = np.append(self._sightings, 1)
        self._last_seen = np.append(self._last_seen, scan)
        self._side = np.append(self._side, 0)
        self._side_at = np.vstack([self._side_at, np.zeros((1, 2))])
        self._mute = np.append(self._mute, 0)
        self._next_id += 1

    def _prune(self, scan: int) -> None:
        keep = (self._sightings >= self.params.min_sightings) | (scan - self._last_seen <= _STALE_SCANS)
        if keep.all():
            return
        self._seg, self._ids, self._sightings = self._seg[keep], self._ids[keep], self._sightings[keep]
        self._last_seen, self._side, self._side_at = self._last_seen[keep], self._side[keep], self._side_at[keep]
        self._mute = self._mute[keep]

    def crossing(self, position: tuple[float, float], scan: int) -> Crossing | None:
        """Update every exit's side of the robot at ``position``; the exit crossed since the last call, if any.

        With several crossed at once (a pose jump), the one whose line is
        nearest the robot is returned; the others only change side.
        """
        if len(self._ids) == 0:
            return None
        p = self.params
        seg = self._seg
        rows, distance, old_side = self._k.update_sides(
            seg,
            self._side,
            self._side_at,
            self._mute,
            self._sightings,
            self._last_seen,
            float(position[0]),
            float(position[1]),
            p.crossing_band,
            p.min_sightings,
            p.recent_scans,
            scan,
        )
        if len(rows) == 0:
            return None
        best: Crossing | None = None
        best_distance = math.inf
        for r, d, (bx, by) in zip(rows.tolist(), distance.tolist(), old_side.tolist()):
            before = (bx, by)
            if d < best_distance and _passes_between(before, position, seg[r], p.crossing_margin):
                best_distance = d
                best = Crossing(int(self._ids[r]), scan, orient_left(seg[r], before), before, position)
        if best is not None:
            # Another track of the same doorway (placed apart by map drift) is the exit just crossed too:
            # it is muted until the robot is on the side it is heading for, so passing its line is no second
            # crossing.
            mids = 0.5 * (seg[:, :2] + seg[:, 2:])
            here = 0.5 * (best.segment[:2] + best.segment[2:])
            twins = np.hypot(mids[:, 0] - here[0], mids[:, 1] - here[1]) <= p.twin_distance
            twins[self._ids == best.track] = False
            for r in np.flatnonzero(twins).tolist():
                ax, ay, bx, by = seg[r]
                before_side = (bx - ax) * (best.before[1] - ay) - (by - ay) * (best.before[0] - ax)
                self._mute[r] = -1 if before_side > 0 else 1
        return best


def _undirected_angle(a: FloatArray, b: FloatArray) -> float:
    da = math.atan2(a[3] - a[1], a[2] - a[0])
    db = math.atan2(b[3] - b[1], b[2] - b[0])
    d = abs(da - db) % math.pi
    return min(d, math.pi - d)


def _passes_between(p: tuple[float, float], q: tuple[float, float], seg: FloatArray, margin: float) -> bool:
    """Whether the path p -> q meets ``seg`` lengthened by ``margin`` at both ends."""
    a, b = seg[:2], seg[2:]
    e = b - a
    length = float(np.hypot(e[0], e[1]))
    if length <= 0.0:
        return False
    u = e / length
    grown = np.concatenate([a - margin * u, b + margin * u])
    return bool(segments_cross(np.array([p[0], p[1], q[0], q[1]]), grown))
