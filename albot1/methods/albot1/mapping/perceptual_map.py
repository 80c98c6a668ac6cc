"""The perceptual map: line surfaces with stable ids, their history and a bounding-box index.

Everything lives in preallocated numpy arrays whose capacity doubles when
full, so a map update is one compiled call on them
(:func:`~albot1.methods.albot1.mapping.kernels.update_surfaces`) with no
Python object per surface. Surfaces are indexed by id (ids are never
reused, so an id names one surface for its whole life). The surfaces
currently in the map also sit in a compact table of *slots* with their
bounding boxes (a deleted surface's slot is filled by the last one), so a
query tests only the live surfaces: its cost follows the size of the map
(the explored area), never the number of surfaces ever made (the route
length). On the full Intel log that is about 2,000 live surfaces out of
60,000 ids. A surface's history is its ``added_at`` scan and the rows of one
event log ``(id, action, scan)`` naming it, oldest first; the per-surface
lists are only built for :meth:`history` and :meth:`properties`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.albot1.mapping.kernels import DELETED, EXTENDED, TRIMMED

IntArray = NDArray[np.int64]

#: The event names of the history, by action code of the event log.
EVENT_NAMES = {EXTENDED: "extended", TRIMMED: "trimmed", DELETED: "deleted"}
_EVENT_CODES = {name: code for code, name in EVENT_NAMES.items()}


class PerceptualMap:
    """Editable surfaces ``(x1, y1, x2, y2)`` in the map (thesis) frame."""

    def __init__(self) -> None:
        cap = 256
        self.seg = np.empty((cap, 4))
        self.alive = np.zeros(cap, dtype=bool)
        self.added_at = np.zeros(cap, dtype=np.int64)
        self.slot_of = np.full(cap, -1, dtype=np.int64)
        #: Live surfaces: slot -> id and bounding box (xmin, ymin, xmax, ymax); slots 0..live-1 are in use.
        self.live_id = np.empty(cap, dtype=np.int64)
        self.live_box = np.empty((cap, 4))
        #: Rows (id, action code, scan) of every extension, trim and deletion, in order.
        self.events = np.empty((cap, 3), dtype=np.int64)
        self.n = 0
        self.live = 0
        self.n_events = 0

    def __len__(self) -> int:
        """Number of surfaces currently in the map."""
        return self.live

    def reserve(self, surfaces: int, events: int) -> None:
        """Make room for ``surfaces`` more ids and ``events`` more events (capacity doubles as needed)."""
        cap = self.seg.shape[0]
        if self.n + surfaces > cap:
            while self.n + surfaces > cap:
                cap *= 2
            self.seg = np.resize(self.seg, (cap, 4))
            alive = np.zeros(cap, dtype=bool)
            alive[: self.n] = self.alive[: self.n]
            self.alive = alive
            self.added_at = np.resize(self.added_at, cap)
            slot_of = np.full(cap, -1, dtype=np.int64)
            slot_of[: self.n] = self.slot_of[: self.n]
            self.slot_of = slot_of
            self.live_id = np.resize(self.live_id, cap)
            self.live_box = np.resize(self.live_box, (cap, 4))
        ecap = self.events.shape[0]
        if self.n_events + events > ecap:
            while self.n_events + events > ecap:
                ecap *= 2
            self.events = np.resize(self.events, (ecap, 3))

    def add(self, segments: FloatArray, scan: int) -> IntArray:
        """Add surfaces ``(m, 4)`` at update ``scan``; returns their new ids."""
        seg = np.asarray(segments, dtype=float).reshape(-1, 4)
        m = seg.shape[0]
        self.reserve(m, 0)
        ids = np.arange(self.n, self.n + m, dtype=np.int64)
        self.seg[ids] = seg
        self.alive[ids] = True
        self.added_at[ids] = scan
        slots = np.arange(self.live, self.live + m, dtype=np.int64)
        self.slot_of[ids] = slots
        self.live_id[slots] = ids
        self.live_box[slots] = np.column_stack(
            [
                np.minimum(seg[:, 0], seg[:, 2]),
                np.minimum(seg[:, 1], seg[:, 3]),
                np.maximum(seg[:, 0], seg[:, 2]),
                np.maximum(seg[:, 1], seg[:, 3]),
            ]
        )
        self.n += m
        self.live += m
        return ids

    def _log(self, sid: int, event: str, scan: int) -> None:
        self.reserve(0, 1)
        self.events[self.n_events] = (sid, _EVENT_CODES[event], scan)
        self.n_events += 1

    def replace(self, sid: int, segment: FloatArray, scan: int, event: str) -> None:
        """Give surface ``sid`` new endpoints (``event``: "extended" or "trimmed")."""
        self._check(sid)
        x1, y1, x2, y2 = (float(v) for v in segment)
        self.seg[sid] = (x1, y1, x2, y2)
        self.live_box[self.slot_of[sid]] = (min(x1, x2), min(y1, y2), max(x1, x2), max(y1, y2))
        self._log(sid, event, scan)

    def delete(self, sid: int, scan: int) -> None:
        """Remove surface ``sid`` (its id and history stay retrievable)."""
        self._check(sid)
        slot = int(self.slot_of[sid])
        last = self.live - 1
        if slot != last:  # the last live surface fills the hole
            moved = int(self.live_id[last])
            self.live_id[slot] = moved
            self.live_box[slot] = self.live_box[last]
            self.slot_of[moved] = slot
        self.slot_of[sid] = -1
        self.live = last
        self.alive[sid] = False
        self._log(sid, "deleted", scan)

    def _check(self, sid: int) -> None:
        if not (0 <= sid < self.n) or not self.alive[sid]:
            raise KeyError(f"surface id {sid} is not in the map")

    def query(self, xmin: float, ymin: float, xmax: float, ymax: float) -> IntArray:
        """Ids (ascending) of the surfaces whose bounding box meets the box."""
        box = self.live_box[: self.live]
        hit = (box[:, 2] >= xmin) & (box[:, 0] <= xmax) & (box[:, 3] >= ymin) & (box[:, 1] <= ymax)
        return np.sort(self.live_id[: self.live][hit])

    def segments(self, ids: IntArray | None = None) -> FloatArray:
        """Endpoints of ``ids`` (default: every surface in the map, by id)."""
        if ids is None:
            ids = self.ids()
        return self.seg[ids].copy()

    def ids(self) -> IntArray:
        """Ids of the surfaces in the map, ascending."""
        return np.flatnonzero(self.alive[: self.n]).astype(np.int64)

    def _histories(self, ids: IntArray) -> list[list[tuple[str, int]]]:
        """The history of each of ``ids``: ``added`` then its events in the order they were logged."""
        log = self.events[: self.n_events]
        order = np.argsort(log[:, 0], kind="stable")
        by_id = log[order]
        starts = np.searchsorted(by_id[:, 0], ids, side="left").tolist()
        ends = np.searchsorted(by_id[:, 0], ids, side="right").tolist()
        codes, scans = by_id[:, 1].tolist(), by_id[:, 2].tolist()
        added_at = self.added_at[ids].tolist()
        return [
            [("added", added_at[r])] + [(EVENT_NAMES[codes[e]], scans[e]) for e in range(starts[r], ends[r])]
            for r in range(len(starts))
        ]

    def history(self, sid: int) -> list[tuple[str, int]]:
        """What happened to surface ``sid``, oldest first, as ``(event, scan)``."""
        if not 0 <= sid < self.n:
            raise KeyError(f"surface id {sid} was never in the map")
        return self._histories(np.asarray([sid], dtype=np.int64))[0]

    def properties(self, ids: IntArray | None = None) -> list[dict[str, Any]]:
        """JSON-able per-surface records for MapData.segment_properties."""
        if ids is None:
            ids = self.ids()
        ids = np.asarray(ids, dtype=np.int64)
        return [
            {"id": i, "added_at": events[0][1], "history": [{"event": e, "scan": s} for e, s in events]}
            for i, events in zip(ids.tolist(), self._histories(ids))
        ]
