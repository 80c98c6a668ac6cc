"""The place memory: places, their visits and the exits between them (thesis 4.1.1, Algorithms 5 and 7).

"The resulting topological map learned is a list of places visited and each
place consists of two pieces of information: an inexact metric map with its
own frame of reference and an exit list ... Each exit has three values: its
whereabouts in the current place, the place it leads to, and the exit of
the place it leads to." (4.1)

A :class:`Place` holds its surfaces and exits in its own frame: the robot's
pose in the perceptual map when its first visit began (the crossing that
entered it; the start pose for the first place). A :class:`Visit` is one
stay in a place, from the crossing that entered it to the crossing that
left it; until it is recognised or closed it belongs to no place. Its
``place_in_map`` is where that place's frame lies in the perceptual map
*now* (the start pose for a new place, the matcher's or the exit
alignment's motion for a recognised one): it brings the visit's surfaces
into the place's frame when the visit is closed, and the place's exits into
the perceptual map when they are predicted (Algorithm 7).

Merging (a visit recognised as a place when it already belongs to another,
4.2.2's P7 found to be P1): the younger place is folded into the older one;
its id stays as an alias so that records that named it still resolve.
Exits are numbered across the whole network; an exit found to be the same
as another on merging keeps an alias to it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.se2 import Pose, between_pose, compose_pose
from albot1.geometry.segments import transform_segments
from albot1.geometry.types import FloatArray


def invert(pose: Pose) -> Pose:
    """``inv(pose)`` for a single pose."""
    return between_pose(pose, (0.0, 0.0, 0.0))


@dataclass
class ExitRecord:
    """An exit of a place: ``segment`` in the place's frame with the place on its left (counter-clockwise side).

    ``learned_map`` is where it was in the perceptual map when first recorded
    (Figure 4.7's "original position", the not-aligned prediction).
    """

    id: int
    segment: FloatArray
    learned_map: FloatArray
    scan: int
    leads_to: int | None = None
    leads_exit: int | None = None


@dataclass
class Place:
    """A node of the network: surfaces and exits in its own frame, and the visits that made it."""

    id: int
    created_scan: int
    frame_map: Pose
    surfaces: FloatArray = field(default_factory=lambda: np.empty((0, 4)))
    #: per surface: seen only through one of the place's exits (part of its map, not of its structure)
    through: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))
    exits: list[ExitRecord] = field(default_factory=list)
    visits: list[int] = field(default_factory=list)
    merged_into: int | None = None
    merged_scan: int | None = None


@dataclass
class Visit:
    """One stay in a place: from the crossing that entered it (``entry``, map frame, the place on its left)."""

    id: int
    first_scan: int
    frame: Pose
    entry: FloatArray | None
    entered_from: tuple[int, int] | None
    place: int | None = None
    place_in_map: Pose | None = None
    last_scan: int | None = None
    left_by: int | None = None
    entry_exit: int | None = None


class PlaceNetwork:
    """Places, visits, exits and their links; the bookkeeping of Algorithms 5 and 7."""

    def __init__(
        self,
        *,
        same_angle: float,
        same_gap: float,
        link_distance: float,
        same_any: Callable[[FloatArray, FloatArray, float, float], tuple[NDArray[np.bool_], NDArray[np.bool_]]],
    ) -> None:
        self.places: list[Place] = []
        self.visits: list[Visit] = []
        self._same_angle = same_angle
        self._same_gap = same_gap
        self._link_distance = link_distance
        self._same_any = same_any
        self._exit_alias: dict[int, int] = {}
        self._next_exit = 0

    # -- lookups -------------------------------------------------------------------------------------------------
    def find(self, place: int) -> int:
        """The place ``place`` is now (following merges)."""
        while self.places[place].merged_into is not None:
            place = self.places[place].merged_into  # type: ignore[assignment]
        return place

    def exit_id(self, exit_id: int) -> int:
        """The exit ``exit_id`` is now (following merges of duplicate exits)."""
        while exit_id in self._exit_alias:
            exit_id = self._exit_alias[exit_id]
        return exit_id

    def exit(self, place: int, exit_id: int) -> ExitRecord | None:
        wanted = self.exit_id(exit_id)
        for record in self.places[self.find(place)].exits:
            if record.id == wanted:
                return record
        return None

    @property
    def current(self) -> Visit:
        return self.visits[-1]

    def live_places(self) -> list[Place]:
        return [p for p in self.places if p.merged_into is None]

    # -- visits ----------------------------------------------------------------------------------------------------
    def start_visit(
        self,
        scan: int,
        frame: Pose,
        entry: FloatArray | None = None,
        entered_from: tuple[int, int] | None = None,
    ) -> Visit:
        visit = Visit(len(self.visits), scan, frame, entry, entered_from)
        self.visits.append(visit)
        return visit

    def assign(self, visit: Visit, place: int, place_in_map: Pose, scan: int) -> int:
        """Visit ``visit`` is place ``place`` (its frame at ``place_in_map``); merges if it already was another.

        Returns the place the visit belongs to afterwards.
        """
        place = self.find(place)
        if visit.place is not None and self.find(visit.place) != place:
            mine = self.find(visit.place)
            assert visit.place_in_map is not None
            keep, drop = (place, mine) if place < mine else (mine, place)
            keep_in_map = place_in_map if keep == place else visit.place_in_map
            drop_in_map = visit.place_in_map if keep == place else place_in_map
            self._merge(keep, drop, between_pose(keep_in_map, drop_in_map), scan)
            place, place_in_map = keep, keep_in_map
        visit.place, visit.place_in_map = place, place_in_map
        if visit.id not in self.places[place].visits:
            self.places[place].visits.append(visit.id)
        self._link_entry(visit)
        return place

    def close(
        self,
        visit: Visit,
        surfaces_map: FloatArray,
        exit_map: FloatArray,
        scan: int,
        through: NDArray[np.bool_] | None = None,
    ) -> tuple[int, int]:
        """Algorithm 5 lines 2-13: the visit's surfaces and the exit just crossed go into its place.

        A visit that is no known place creates one (line 9) whose frame is
        the visit's start pose; a recognised visit's description is combined
        with its place's (line 11). ``through`` flags the surfaces seen only
        through an exit. Returns ``(place, exit id)`` of the exit crossed.
        """
        if visit.place is None:
            place = Place(len(self.places), scan, visit.frame)
            self.places.append(place)
            self.assign(visit, place.id, visit.frame, scan)
        assert visit.place is not None and visit.place_in_map is not None
        place = self.places[self.find(visit.place)]
        to_own = invert(visit.place_in_map)
        flags = np.zeros(len(surfaces_map), dtype=bool) if through is None else np.asarray(through, dtype=bool)
        place.surfaces, place.through = self._combine(
            place.surfaces, place.through, transform_segments(to_own, surfaces_map), flags
        )
        exit_id = self._add_exit(place, transform_segments(to_own, exit_map)[0], exit_map, scan)
        visit.last_scan, visit.left_by = scan, exit_id
        return place.id, exit_id

    def _link_entry(self, visit: Visit) -> None:
        """Line 12: the exit the visit came in by, recorded in its place and linked both ways."""
        if visit.entry is None or visit.entry_exit is not None or visit.place is None:
            return
        assert visit.place_in_map is not None
        place = self.places[self.find(visit.place)]
        own = transform_segments(invert(visit.place_in_map), visit.entry)[0]
        visit.entry_exit = self._add_exit(place, own, visit.entry, visit.first_scan)
        if visit.entered_from is not None:
            self.link(visit.entered_from, (place.id, visit.entry_exit))

    def link(self, a: tuple[int, int], b: tuple[int, int]) -> None:
        """Exit ``a[1]`` of place ``a[0]`` leads to exit ``b[1]`` of place ``b[0]`` and back."""
        ra, rb = self.exit(*a), self.exit(*b)
        if ra is None or rb is None:
            return
        ra.leads_to, ra.leads_exit = self.find(b[0]), rb.id
        rb.leads_to, rb.leads_exit = self.find(a[0]), ra.id

    def leads(self, place: int, exit_id: int) -> tuple[int, int] | None:
        """Where exit ``exit_id`` of ``place`` leads: ``(place, exit)``, or None when not known."""
        record = self.exit(place, exit_id)
        if record is None or record.leads_to is None or record.leads_exit is None:
            return None
        return self.find(record.leads_to), self.exit_id(record.leads_exit)

    # -- combining descriptions ----------------------------------------------------------------------------------
    def _add_exit(self, place: Place, own: FloatArray, in_map: FloatArray, scan: int) -> int:
        """The id of ``own`` among the place's exits: an existing one within the link distance, else a new one."""
        found = self.same_exit(place, own)
        if found is not None:
            return found
        record = ExitRecord(self._next_exit, np.asarray(own, dtype=float).copy(), in_map.copy(), scan)
        self._next_exit += 1
        place.exits.append(record)
        return record.id

    def same_exit(self, place: Place, own: FloatArray) -> int | None:
        """The exit of ``place`` whose midpoint is within the link distance of ``own``'s (the nearest), or None."""
        mid = 0.5 * (own[:2] + own[2:])
        best, best_distance = None, self._link_distance
        for record in place.exits:
            rmid = 0.5 * (record.segment[:2] + record.segment[2:])
            distance = math.hypot(rmid[0] - mid[0], rmid[1] - mid[1])
            if distance <= best_distance:
                best, best_distance = record.id, distance
        return best

    def _combine(
        self, old: FloatArray, old_through: NDArray[np.bool_], new: FloatArray, new_through: NDArray[np.bool_]
    ) -> tuple[FloatArray, NDArray[np.bool_]]:
        """``old`` plus the surfaces of ``new`` that are not already there (same within 5 deg and 40 cm).

        A surface once seen from inside the place stays part of its structure.
        """
        if len(new) == 0:
            return old, old_through
        if len(old) == 0:
            return new.copy(), new_through.copy()
        new = np.ascontiguousarray(new, dtype=float)
        old = np.ascontiguousarray(old, dtype=float)
        known, _ = self._same_any(new, old, self._same_angle, self._same_gap)
        _, seen_inside = self._same_any(new[~new_through], old, self._same_angle, self._same_gap)
        through = old_through & ~seen_inside
        fresh = ~known
        return np.vstack([old, new[fresh]]), np.concatenate([through, new_through[fresh]])

    def _merge(self, keep: int, drop: int, drop_in_keep: Pose, scan: int) -> None:
        """Fold place ``drop`` (its frame at ``drop_in_keep`` in ``keep``'s frame) into ``keep``."""
        k, d = self.places[keep], self.places[drop]
        k.surfaces, k.through = self._combine(
            k.surfaces, k.through, transform_segments(drop_in_keep, d.surfaces), d.through
        )
        for record in d.exits:
            moved = transform_segments(drop_in_keep, record.segment)[0]
            same = self.same_exit(k, moved)
            if same is None:  # a new exit of the kept place, with its id and links
                record.segment = moved
                k.exits.append(record)
                continue
            self._exit_alias[record.id] = same
            target = self.exit(keep, same)
            assert target is not None
            if target.leads_to is None and record.leads_to is not None:
                target.leads_to, target.leads_exit = record.leads_to, record.leads_exit
        k.visits.extend(v for v in d.visits if v not in k.visits)
        d.merged_into, d.merged_scan = keep, scan
        d.surfaces, d.through, d.exits = np.empty((0, 4)), np.zeros(0, dtype=bool), []
        for visit in self.visits:
            if visit.place is not None and self.find(visit.place) == keep and visit.place != keep:
                assert visit.place_in_map is not None
                visit.place = keep
                visit.place_in_map = compose_pose(visit.place_in_map, invert(drop_in_keep))


def same_surfaces(a: FloatArray, b: FloatArray, max_angle: float, max_gap: float) -> NDArray[np.bool_]:
    """``(len(a), len(b))``: pairs in the same direction (within ``max_angle``) and within ``max_gap``.

    The gap is the smallest endpoint-to-segment distance both ways (segments
    that cross at a small angle are near there too).
    """
    da = np.arctan2(a[:, 3] - a[:, 1], a[:, 2] - a[:, 0])
    db = np.arctan2(b[:, 3] - b[:, 1], b[:, 2] - b[:, 0])
    turn = np.abs((da[:, None] - db[None, :] + np.pi) % (2 * np.pi) - np.pi)
    gap = np.minimum(
        np.minimum(_point_segments(a[:, :2], b), _point_segments(a[:, 2:], b)),
        np.minimum(_point_segments(b[:, :2], a).T, _point_segments(b[:, 2:], a).T),
    )
    return (turn < max_angle) & (gap <= max_gap)


def _point_segments(points: FloatArray, segments: FloatArray) -> FloatArray:
    """``(len(points), len(segments))`` point-to-segment distances."""
    a, b = segments[None, :, :2], segments[None, :, 2:]
    e = b - a
    rel = points[:, None, :] - a
    l2 = np.maximum((e * e).sum(axis=-1), 1e-300)
    t = np.clip((rel * e).sum(axis=-1) / l2, 0.0, 1.0)
    near = a + t[..., None] * e
    distances: FloatArray = np.hypot(points[:, None, 0] - near[..., 0], points[:, None, 1] - near[..., 1])
    return distances
