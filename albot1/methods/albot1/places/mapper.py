"""``albot1-places``: the chapter-3 perceptual mapper with chapter 4's network of places on top.

The chapter-3 :class:`~albot1.methods.albot1.mapping.mapper.Albot1Mapper`
runs unchanged inside; this class listens to its map updates
(:attr:`~albot1.methods.albot1.mapping.mapper.Albot1Mapper.on_update`) and,
after each scan:

1. marks every surface the update brought into the map with the current
   visit, and counts the map surfaces the view co-locates with per
   remembered place (4.1.2);
2. detects exits in the view and tracks them into the map; when one is
   crossed, closes the current place and opens the next (Algorithm 5), checks
   whether the exit leads to a known place (line 13) and, if so, brings that
   place's exits into the map aligned at the exit (Algorithm 7), then forces
   a map update so the surfaces in view start the new place (line 16);
3. when more than n surfaces of a remembered place co-located in an update,
   matches the current place's structure with it (Algorithm 6) and, on
   confirmation, merges and predicts its exits (Algorithm 8).

Poses, map and counters are the chapter-3 mapper's (the forced updates
change them a little: they are updates); the network leaves as the run
folder's ``places.json`` and ``places.graphml`` (``MapperOutput.files``).
Everything runs in the thesis frame and is handed out in the REP-103 map
frame, as chapter 3's output.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel

from albot1.config.presets import TomlPresets
from albot1.contract import MapperOutput
from albot1.data.model import Frame
from albot1.geometry.se2 import Pose
from albot1.geometry.segments import transform_segments
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.mapper import Albot1Mapper, UpdateEvent
from albot1.methods.albot1.mapping.update import view_polygon
from albot1.methods.albot1.places.config import Albot1PlacesConfig
from albot1.methods.albot1.places.counts import PlacesCounts, places_counters
from albot1.methods.albot1.places.exits import Crossing, ExitTracker
from albot1.methods.albot1.places.kernels import PlacesKernels
from albot1.methods.albot1.places.matcher import confirm, structural, trigger_threshold
from albot1.methods.albot1.places.memory import Place, PlaceNetwork, Visit, invert, same_surfaces
from albot1.methods.albot1.places.navigation import Prediction, align_at_exit, nearest_prediction, predict
from albot1.methods.albot1.places.network import load_graph_library, network_files
from albot1.methods.albot1.warm_up import together, warm_up

IntArray = NDArray[np.int64]


#: The current place's empty space is that of its last this many updates (bounds the conflict test's cost).
_MAX_POLYGONS = 30


class Albot1PlacesMapper:
    """Albot1 with its network of places (thesis chapter 4, Algorithms 5-8)."""

    name: ClassVar[str] = "albot1-places"
    config_model: ClassVar[type[BaseModel]] = Albot1PlacesConfig
    presets = TomlPresets()

    def __init__(self, config: Albot1PlacesConfig, *, seed: int = 0) -> None:
        self.config = config
        self.inner = Albot1Mapper(config, seed=seed)
        self.inner.on_update = self._on_update
        self._k = PlacesKernels(config.accelerate)
        self._match = config.match_params()
        self.exits = ExitTracker(config.exit_params(), self._k)
        self._same_angle = math.radians(config.match_angle_deg)
        self._same_gap = config.match_gap_m
        self.network = PlaceNetwork(
            same_angle=self._same_angle,
            same_gap=self._same_gap,
            link_distance=config.exit_link_distance_m,
            same_any=self._k.same_any,
        )
        self._labels: list[set[int]] = []  # map surface id -> the visits it belongs to (see _map_evidence)
        self._placed_cache: dict[int, tuple[Any, FloatArray]] = {}
        self._structure_cache: dict[int, tuple[Any, FloatArray]] = {}
        self._pool: tuple[FloatArray, NDArray[np.int64], NDArray[np.int64], FloatArray] | None = None
        self._members: dict[int, set[int]] = {}  # visit -> the map surface ids marked with it
        self._through: set[int] = set()  # surfaces the current visit saw only through an exit
        self._polygons: list[FloatArray] = []  # the view polygons of the current visit's updates (seen empty)
        self._evidence: dict[int, set[int]] = {}  # place -> its surfaces the current visit's updates co-located with
        self._ahead: dict[int, dict[int, set[int]]] = {}  # exit track -> the same, for what was seen through it
        self._fresh = False  # evidence grew since the last check
        self._attempts: dict[tuple[int, int], tuple[int, int]] = {}  # (visit, place) -> (surfaces, scan) of a failure
        self._predicted: list[Prediction] = []
        self._predictions: list[dict[str, Any]] = []
        self._revisits: list[dict[str, Any]] = []
        self._crossings: list[dict[str, Any]] = []
        self._counts = PlacesCounts()
        self._n = 0

    #: warm-ups made inside it are compiled as one (the bench's forkserver warms every preset so)
    warm_up_together = staticmethod(together)

    def warm_up(self, announce: Callable[[str], None] | None = None) -> None:
        """Compile every kernel, the places layer's too, and import the graph library, before the timed loop.

        (:meth:`Albot1Mapper.warm_up`; :func:`load_graph_library`: ``finish`` then only writes the network.)
        """
        load_graph_library()
        if self.config.accelerate:
            warm_up((*self.inner.kernels, self._k), announce, skip=MappingKernels.not_called(self.config.pose_estimate))

    # -- per scan ----------------------------------------------------------------------------------------------
    def process(self, frame: Frame) -> None:
        n = self._n
        if n == 0:
            self.network.start_visit(0, (0.0, 0.0, 0.0))
        self.inner.process(frame)
        view, pose = self.inner.last_view, self.inner.last_pose
        assert view is not None and pose is not None
        self.exits.observe(view, pose, n)
        crossing = self.exits.crossing((pose[0], pose[1]), n)
        if crossing is not None:
            self._cross(crossing, pose, n)
        if self._fresh and not self.exits.near((pose[0], pose[1]), self.config.recognition_exit_clearance_m, n):
            # In a doorway the check waits until the robot is clear of it.
            self._recognise(pose, n)
            self._fresh = False
        self._n += 1

    def _on_update(self, event: UpdateEvent) -> None:
        """Gather re-visit evidence from the update, then mark the view's surfaces with the current visit."""
        current = self.network.current
        view = event.view_map
        if len(view) == 0:
            return
        robot = (event.pose[0], event.pose[1])
        poly = view_polygon(view, robot, "robot_and_endpoints")
        # which view surfaces were seen through an exit (the view's rows are the map ids' rows)
        through = self.exits.beyond(robot, 0.5 * (view[:, :2] + view[:, 2:]), event.scan)
        if self.config.revisit_evidence == "memory":
            self._memory_evidence(event, poly)
        else:
            self._map_evidence(event)
        self._polygons.append(poly)
        del self._polygons[:-_MAX_POLYGONS]
        members = self._members.setdefault(current.id, set())
        ids = event.outcome.view_ids.tolist()
        deleted = event.outcome.deleted.tolist()
        members.difference_update(deleted)  # the visit's marked surfaces still in the map
        self._through.difference_update(deleted)
        members.update(ids)
        self._through.difference_update(ids)
        self._through.update(sid for sid, exit_id in zip(ids, through.tolist()) if exit_id >= 0)
        if self.config.revisit_evidence == "perceptual_map":
            labels = self._labels
            while len(labels) <= max(ids):
                labels.append(set())
            for sid in ids:
                labels[sid].add(current.id)

    def _add_evidence(self, place: int, key: int, exit_id: int) -> None:
        """Surface ``key`` of ``place`` co-located: here (``exit_id`` -1) or seen through exit ``exit_id``."""
        evidence = self._evidence if exit_id < 0 else self._ahead.setdefault(exit_id, {})
        evidence.setdefault(place, set()).add(key)
        self._fresh = self._fresh or exit_id < 0

    def _map_evidence(self, event: UpdateEvent) -> None:
        """``revisit_evidence = "perceptual_map"``: the places of the map surfaces the update deletes or edits.

        The literal 4.1.2: "it checks to which places these surfaces belong
        before it deletes them". A surface belongs to every visit that brought
        it into the map, and a surface an update adds in place of one it
        deleted (the same within 5 degrees and 40 cm: the same wall seen
        again) inherits that one's visits, since the perceptual map replaces
        surfaces rather than editing them. Only surfaces longer than
        ``place_surface_min_m`` count: "in the implementation, it is
        considered surfaces with a length > 40cm" (4.1.2), and n is counted
        in such surfaces too (:func:`trigger_threshold` of the structure).
        """
        out = event.outcome
        network = self.network
        labels = self._labels
        top = int(max(out.view_ids.max(initial=-1), out.added.max(initial=-1))) + 1
        while len(labels) < top:
            labels.append(set())
        touched = np.concatenate([out.deleted, out.extended, out.trimmed])
        if len(touched):
            seg = self.inner.map.segments(touched)
            # 4.1.2 "it is considered surfaces with a length > 40cm": shorter pieces are no evidence
            longer = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1]) > self._match.min_surface
            touched, seg = touched[longer], seg[longer]
            through = self.exits.beyond((event.pose[0], event.pose[1]), 0.5 * (seg[:, :2] + seg[:, 2:]), event.scan)
            excluded = self._excluded()
            for sid, exit_id in zip(touched.tolist(), through.tolist()):
                places = {network.find(p) for p in (network.visits[v].place for v in labels[sid]) if p is not None}
                for place in places - excluded:
                    self._add_evidence(place, sid, exit_id)
        if len(out.added) and len(out.deleted):
            pmap = self.inner.map
            same = same_surfaces(pmap.segments(out.added), pmap.segments(out.deleted), self._same_angle, self._same_gap)
            deleted = out.deleted.tolist()
            for row, col in zip(*np.nonzero(same)):
                labels[int(out.added[row])] |= labels[deleted[col]]

    def _memory_evidence(self, event: UpdateEvent, poly: FloatArray) -> None:
        """``revisit_evidence = "memory"``: the remembered places' structure where the map held it when learned.

        Each place's structure (its own surfaces, not those seen through its
        exits, merged where collinear) is put back where its frame lay in the
        perceptual map when it was created,
        and co-locate with the incoming view when Algorithm 3 would delete or
        edit them: an end inside the view's polygon or within the delete
        margin (the chapter-3 rule and kernel). That is the perceptual map's
        content before later updates deleted or merged it (the thesis's
        limitation 3); see docs/places.md.
        """
        view = event.view_map
        cfg = self.config
        robot = (event.pose[0], event.pose[1])
        if cfg.update_polygon != "robot_and_endpoints":
            poly = view_polygon(view, robot, cfg.update_polygon)
        segments, owner, key, box = self._memory_pool()
        if len(segments) == 0:
            return
        hit = self._k.colocated(
            segments,
            box,
            owner,
            np.fromiter(self._excluded(), dtype=np.int64),
            poly,
            np.ascontiguousarray(view),
            cfg.delete_margin_m,
            cfg.delete_margin_from == "surfaces",
        )
        if len(hit) == 0:
            return
        seg = segments[hit]
        through = self.exits.beyond(robot, 0.5 * (seg[:, :2] + seg[:, 2:]), event.scan)
        owners, keys = owner[hit], key[hit]
        for exit_id in np.unique(through).tolist():
            evidence = self._evidence if exit_id < 0 else self._ahead.setdefault(exit_id, {})
            side = through == exit_id
            for place in np.unique(owners[side]).tolist():
                evidence.setdefault(place, set()).update(keys[side & (owners == place)].tolist())
            self._fresh = self._fresh or exit_id < 0

    def _memory_pool(self) -> tuple[FloatArray, NDArray[np.int64], NDArray[np.int64], FloatArray]:
        """Every live place's placed structure in one array: segments, owning place, index in it, bounding boxes.

        Rebuilt only when the network changed (a crossing or a recognition), so
        an update tests all remembered places with one kernel call.
        """
        if self._pool is None:
            parts = [(place.id, self._placed(place)) for place in self.network.live_places()]
            parts = [(pid, seg) for pid, seg in parts if len(seg)]
            if parts:
                segments = np.ascontiguousarray(np.vstack([seg for _, seg in parts]))
                owner = np.concatenate([np.full(len(seg), pid, dtype=np.int64) for pid, seg in parts])
                key = np.concatenate([np.arange(len(seg), dtype=np.int64) for _, seg in parts])
            else:
                segments, owner, key = np.empty((0, 4)), np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
            xs, ys = segments[:, 0::2], segments[:, 1::2]
            box = (
                np.column_stack([xs.min(axis=1), ys.min(axis=1), xs.max(axis=1), ys.max(axis=1)])
                if len(segments)
                else np.empty((0, 4))
            )
            self._pool = (segments, owner, key, box)
        return self._pool

    def _placed(self, place: Place) -> FloatArray:
        """A place's structure in the map where its frame lay when created (cached until the place changes).

        The structure (:meth:`_structure`) is what the trigger's n is counted
        in, so the co-locating surfaces are counted in the same units.
        """
        key = (len(place.surfaces), place.frame_map)
        cached = self._placed_cache.get(place.id)
        if cached is None or cached[0] != key:
            own = self._structure(place)
            cached = (key, transform_segments(place.frame_map, own) if len(own) else np.empty((0, 4)))
            self._placed_cache[place.id] = cached
        return cached[1]

    def _structure(self, place: Place) -> FloatArray:
        """A remembered place's structure (:func:`structural` of its own surfaces), cached until it changes."""
        key = (len(place.surfaces), int(np.count_nonzero(place.through)))
        cached = self._structure_cache.get(place.id)
        if cached is None or cached[0] != key:
            cached = (key, structural(place.surfaces[~place.through], self._match, self._k))
            self._structure_cache[place.id] = cached
        return cached[1]

    def _excluded(self) -> set[int]:
        """The current visit's place and the one just left: never candidates for a re-visit."""
        network = self.network
        return {network.find(v.place) for v in network.visits[-2:] if v.place is not None}

    def _visit_surfaces(self, visit: Visit) -> tuple[FloatArray, NDArray[np.bool_]]:
        """The map surfaces (thesis map frame) marked with the current ``visit`` (Algorithm 5 lines 2-6).

        With a flag per surface: seen only through an exit.
        """
        members = self._members.get(visit.id, set())
        ids = np.sort(np.fromiter(members, dtype=np.int64, count=len(members)))
        through = np.isin(ids, np.fromiter(self._through, dtype=np.int64, count=len(self._through)))
        return self.inner.map.segments(ids), through

    # -- Algorithms 5 and 7: an exit crossed ---------------------------------------------------------------------
    def _cross(self, crossing: Crossing, pose: Pose, n: int) -> None:
        network, counts = self.network, self._counts
        counts.exits_crossed += 1
        visit = network.current
        compared = nearest_prediction(self._predicted, crossing.segment, 2.0 * self.config.exit_link_distance_m)
        surfaces, through = self._visit_surfaces(visit)
        place, exit_id = network.close(visit, surfaces, crossing.segment, n, through)
        self._pool = None  # the network changed
        self._through, self._polygons = set(), []
        self._members.pop(visit.id, None)  # a closed visit's surfaces are in its place now
        entry = np.concatenate([crossing.segment[2:], crossing.segment[:2]])  # the place entered on its left
        target = network.leads(place, exit_id)
        nxt = network.start_visit(n, pose, entry, (place, exit_id))
        record: dict[str, Any] = {
            "scan": n,
            "exit": exit_id,
            "from_visit": visit.id,
            "from_place": place,
            "to_visit": nxt.id,
            "segment": entry,
            "robot": pose,
            "prediction": None,
        }
        if compared is not None:
            prediction, aligned_m, not_aligned_m = compared
            record["prediction"] = {
                "exit": prediction.exit,
                "place": prediction.place,
                "predicted_at_scan": prediction.scan,
                "aligned": prediction.aligned,
                "not_aligned": prediction.not_aligned,
                "aligned_distance_m": aligned_m,
                "not_aligned_distance_m": not_aligned_m,
            }
        self._predicted = []
        # What co-located beyond the exit just crossed is now evidence about the current place.
        ahead: dict[int, set[int]] = {}
        for twin in self.exits.twins(crossing.track):
            for place, ids in self._ahead.pop(twin, {}).items():
                ahead.setdefault(place, set()).update(ids)
        self._ahead.clear()
        self._evidence, self._fresh = ahead, bool(ahead)
        if target is not None:
            known, known_exit = target
            landing = network.exit(known, known_exit)
            assert landing is not None
            place_in_map = align_at_exit(landing.segment, entry)
            known = network.assign(nxt, known, place_in_map, n)
            counts.revisits_by_exit += 1
            self._revisits.append(
                {"scan": n, "visit": nxt.id, "place": known, "how": "exit", "exit": exit_id, "matches": None}
            )
            self._predict(nxt, n)
        record["to_place"] = nxt.place
        self._crossings.append(record)
        counts.updates_forced += 1
        self.inner.force_update()  # line 16: the surfaces in view re-enter the map, marked with the new visit

    def _predict(self, visit: Visit, n: int) -> None:
        """Algorithms 7-8 step 13: the exits of the visit's place, in the map where the place now lies."""
        assert visit.place is not None and visit.place_in_map is not None
        place = self.network.places[self.network.find(visit.place)]
        skip = None if visit.entry_exit is None else self.network.exit_id(visit.entry_exit)
        self._predicted = predict(place.exits, place.id, visit.place_in_map, n, skip)
        for p in self._predicted:
            self._predictions.append(
                {
                    "scan": n,
                    "visit": visit.id,
                    "place": p.place,
                    "exit": p.exit,
                    "aligned": p.aligned,
                    "not_aligned": p.not_aligned,
                }
            )

    # -- Algorithms 6 and 8: a place re-visited -----------------------------------------------------------------
    def _recognise(self, pose: Pose, n: int) -> None:
        network, params = self.network, self._match
        visit = network.current
        excluded = self._excluded()
        current_all: FloatArray | None = None
        current: FloatArray | None = None
        counts = Counter({network.find(p): len(ids) for p, ids in self._evidence.items()})
        for place_id, count in sorted(counts.items(), key=lambda item: (-item[1], item[0])):
            if place_id in excluded:
                continue
            place = network.places[place_id]
            remembered = self._structure(place)
            if count <= trigger_threshold(len(remembered), params):
                continue
            key = (visit.id, place_id)
            last = self._attempts.get(key)
            size = len(self._members.get(visit.id, ()))
            if last is not None and (size < last[0] + params.retry_growth or n < last[1] + params.retry_scans):
                continue
            if current_all is None:
                current_all, seen_through = self._visit_surfaces(visit)
                current = self._this_side(structural(current_all[~seen_through], params, self._k), pose, n)
            assert current is not None
            self._counts.match_attempts += 1
            match = confirm(current, remembered, pose, self._polygons, place.frame_map, params, self._k)
            if not match.confirmed:
                self._attempts[key] = (size, n)
                continue
            place_in_map = self._align_at_entry(visit, place_id, match.place_in_map)
            before = None if visit.place is None else network.find(visit.place)
            if before is not None and not self._same_place(before, place_id, place_in_map):
                self._counts.merges_refused += 1
                self._attempts[key] = (size, n)
                continue
            now = network.assign(visit, place_id, place_in_map, n)
            self._pool = None
            self._counts.revisits_by_structure += 1
            self._revisits.append(
                {
                    "scan": n,
                    "visit": visit.id,
                    "place": place_id,
                    "how": "structure",
                    "exit": None,
                    "matches": match.matches,
                    "merged": None if before is None else sorted({before, place_id}),
                    "kept": now,
                }
            )
            self._predict(visit, n)
            return

    def _this_side(self, surfaces: FloatArray, pose: Pose, scan: int) -> FloatArray:
        """The surfaces not seen through an exit: the current place's own structure (see docs/places.md)."""
        mid = 0.5 * (surfaces[:, :2] + surfaces[:, 2:])
        return np.ascontiguousarray(surfaces[self.exits.beyond((pose[0], pose[1]), mid, scan) < 0])

    def _same_place(self, known: int, other: int, other_in_map: Pose) -> bool:
        """Before merging: do the visit's place and the one just matched share their structure where they lie?

        The visit already is ``known`` (at its ``place_in_map``); confirming
        ``other`` too says they are one place, so their own surfaces, each
        placed where the map now has it, must co-locate (as many as a match
        needs). A room matched while the doorway view still shows its
        neighbour fails this and is not merged.
        """
        network, params = self.network, self._match
        visit = network.current
        assert visit.place_in_map is not None
        a, b = network.places[known], network.places[other]
        mine = transform_segments(visit.place_in_map, a.surfaces[~a.through])
        theirs = transform_segments(other_in_map, b.surfaces[~b.through])
        if len(mine) == 0 or len(theirs) == 0:
            return False
        same = same_surfaces(
            structural(mine, params, self._k), structural(theirs, params, self._k), self._same_angle, self._same_gap
        )
        return int(np.count_nonzero(same.any(axis=1))) >= params.min_matches

    def _align_at_entry(self, visit: Visit, place_id: int, place_in_map: Pose) -> Pose:
        """Re-align a matched place at the exit the visit came in by, when the place has that exit (Algorithm 8)."""
        if visit.entry is None:
            return place_in_map
        own = transform_segments(invert(place_in_map), visit.entry)[0]
        place = self.network.places[place_id]
        same = self.network.same_exit(place, own)
        if same is None:
            return place_in_map
        record = self.network.exit(place_id, same)
        assert record is not None
        return align_at_exit(record.segment, visit.entry)

    # -- output ------------------------------------------------------------------------------------------------
    def finish(self) -> MapperOutput:
        out = self.inner.finish()
        network = self.network
        counters = places_counters(out.counters, network, self.exits, self._counts, self._crossings)
        files = network_files(
            network,
            crossings=self._crossings,
            revisits=self._revisits,
            predictions=self._predictions,
            scans=self._n,
            config=self.config,
        )
        extras = dict(out.extras)
        extras["places"] = {"file": "places.json", "graph": "places.graphml"}
        return MapperOutput(poses=out.poses, map=out.map, counters=counters, extras=extras, files=files)
