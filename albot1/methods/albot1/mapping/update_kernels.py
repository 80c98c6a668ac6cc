"""Algorithm 3 of the thesis (the map update of one view) as one compiled call.

The perceptual map keeps its surfaces in preallocated arrays
(:class:`~albot1.methods.albot1.mapping.perceptual_map.PerceptualMap`), so
the whole update (box query, endpoint classification, deletions, extensions,
trims and additions) runs here without a Python call per surface: that was
most of a thesis scan's cost (``docs/albot1-mapper.md``, "Measured"). The
geometric steps are the kernels of :mod:`albot1.methods.albot1.mapping.kernels`,
compiled into this loop.
"""

from __future__ import annotations

import numpy as np

from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import jitable, kernel
from albot1.methods.albot1.mapping.kernels import (
    DELETED,
    EXTENDED,
    KEEP,
    BoolArray,
    IntArray,
    covered,
    polygon_points,
    resolve_partial,
)
from albot1.methods.albot1.ordering import stable_order


@jitable
def _drop_surface(
    sid: int, alive: BoolArray, slot_of: IntArray, live_id: IntArray, live_box: FloatArray, live: int
) -> int:
    """Take ``sid`` out of the live table (the last live surface fills its slot); returns the new live count."""
    slot = slot_of[sid]
    last = live - 1
    if slot != last:
        moved = live_id[last]
        live_id[slot] = moved
        for c in range(4):
            live_box[slot, c] = live_box[last, c]
        slot_of[moved] = slot
    slot_of[sid] = -1
    alive[sid] = False
    return last


@kernel
def update_surfaces(
    seg: FloatArray,
    alive: BoolArray,
    added_at: IntArray,
    slot_of: IntArray,
    live_id: IntArray,
    live_box: FloatArray,
    events: IntArray,
    n: int,
    live: int,
    n_events: int,
    view: FloatArray,
    robot_x: float,
    robot_y: float,
    with_robot: bool,
    scan: int,
    margin: float,
    max_angle: float,
    max_distance: float,
    clip: bool,
    surfaces_only: bool,
) -> tuple[IntArray, IntArray, IntArray, IntArray, IntArray, int, int, int]:
    """Algorithm 3 on the arrays of a :class:`~albot1.methods.albot1.mapping.perceptual_map.PerceptualMap`.

    ``seg``/``alive``/``added_at``/``slot_of`` are indexed by surface id
    (``n`` ids so far), ``live_id``/``live_box`` by slot (``live`` in use),
    ``events`` rows ``(id, action, scan)`` (``n_events`` so far); the caller
    has made room for ``len(view)`` more ids and ``live`` more events. The
    view ``(m, 4)`` is in the map, seen from ``(robot_x, robot_y)``; its polygon
    (:func:`polygon_points`) includes that point when ``with_robot``. In order: the live
    surfaces whose bounding box meets the polygon's grown box (ascending id)
    have their endpoints classified (:func:`covered`); those with both ends covered
    are deleted, those with one are resolved (:func:`resolve_partial`) and
    deleted, extended or trimmed; every view surface no map surface took is
    added. Returns the map id of each view surface, the deleted, extended,
    trimmed and added ids, and the new ``n``, ``live`` and ``n_events``.
    """
    m = view.shape[0]
    view_ids = np.empty(m, dtype=np.int64)
    for j in range(m):  # a loop, not np.full: one numpy routine less to compile
        view_ids[j] = -1
    deleted = np.empty(live, dtype=np.int64)
    extended = np.empty(live, dtype=np.int64)
    trimmed = np.empty(live, dtype=np.int64)
    n_del = 0
    n_ext = 0
    n_trim = 0
    if m > 0:
        poly = polygon_points(view, robot_x, robot_y, with_robot)
        lo_x = poly[0, 0]
        lo_y = poly[0, 1]
        hi_x = poly[0, 0]
        hi_y = poly[0, 1]
        for v in range(1, poly.shape[0]):
            lo_x = min(lo_x, poly[v, 0])
            lo_y = min(lo_y, poly[v, 1])
            hi_x = max(hi_x, poly[v, 0])
            hi_y = max(hi_y, poly[v, 1])
        lo_x -= margin
        lo_y -= margin
        hi_x += margin
        hi_y += margin
        hits = np.empty(live, dtype=np.int64)
        k = 0
        for slot in range(live):
            if (
                live_box[slot, 2] >= lo_x
                and live_box[slot, 0] <= hi_x
                and live_box[slot, 3] >= lo_y
                and live_box[slot, 1] <= hi_y
            ):
                hits[k] = live_id[slot]
                k += 1
        # ascending id (unique, so any sort gives this order); numba's np.sort would add ~1 s to a cold compile
        order = stable_order(hits[:k])
        cand = np.empty(k, dtype=np.int64)
        for r in range(k):
            cand[r] = hits[order[r]]
        if k > 0:
            segs = np.empty((k, 4))
            for r in range(k):
                for c in range(4):
                    segs[r, c] = seg[cand[r], c]
            p1_covered = np.empty(k, dtype=np.bool_)
            partial = np.empty(k, dtype=np.int64)
            n_partial = 0
            for r in range(k):
                c1 = covered(poly, view, segs[r, 0], segs[r, 1], margin, surfaces_only)
                c2 = covered(poly, view, segs[r, 2], segs[r, 3], margin, surfaces_only)
                p1_covered[r] = c1
                inside = int(c1) + int(c2)
                if inside == 2:
                    sid = cand[r]
                    live = _drop_surface(sid, alive, slot_of, live_id, live_box, live)
                    events[n_events, 0] = sid
                    events[n_events, 1] = DELETED
                    events[n_events, 2] = scan
                    n_events += 1
                    deleted[n_del] = sid
                    n_del += 1
                elif inside == 1:
                    partial[n_partial] = r
                    n_partial += 1
            if n_partial > 0:
                p_segs = np.empty((n_partial, 4))
                p1_inside = np.empty(n_partial, dtype=np.bool_)
                for q in range(n_partial):
                    for c in range(4):
                        p_segs[q, c] = segs[partial[q], c]
                    p1_inside[q] = p1_covered[partial[q]]
                action, new_segs, match = resolve_partial(
                    p_segs,
                    p1_inside,
                    view,
                    view_ids >= 0,
                    poly,
                    max_angle,
                    max_distance,
                    clip,
                    margin,
                    surfaces_only,
                )
                for q in range(n_partial):
                    sid = cand[partial[q]]
                    if match[q] >= 0:
                        view_ids[match[q]] = sid
                    act = action[q]
                    if act == KEEP:
                        continue
                    events[n_events, 0] = sid
                    events[n_events, 1] = act
                    events[n_events, 2] = scan
                    n_events += 1
                    if act == DELETED:
                        live = _drop_surface(sid, alive, slot_of, live_id, live_box, live)
                        deleted[n_del] = sid
                        n_del += 1
                        continue
                    x1 = new_segs[q, 0]
                    y1 = new_segs[q, 1]
                    x2 = new_segs[q, 2]
                    y2 = new_segs[q, 3]
                    seg[sid, 0] = x1
                    seg[sid, 1] = y1
                    seg[sid, 2] = x2
                    seg[sid, 3] = y2
                    slot = slot_of[sid]
                    live_box[slot, 0] = min(x1, x2)
                    live_box[slot, 1] = min(y1, y2)
                    live_box[slot, 2] = max(x1, x2)
                    live_box[slot, 3] = max(y1, y2)
                    if act == EXTENDED:
                        extended[n_ext] = sid
                        n_ext += 1
                    else:
                        trimmed[n_trim] = sid
                        n_trim += 1
    n_fresh = 0
    for j in range(m):
        if view_ids[j] < 0:
            n_fresh += 1
    added = np.empty(n_fresh, dtype=np.int64)
    a = 0
    for j in range(m):
        if view_ids[j] >= 0:
            continue
        sid = n + a
        x1 = view[j, 0]
        y1 = view[j, 1]
        x2 = view[j, 2]
        y2 = view[j, 3]
        seg[sid, 0] = x1
        seg[sid, 1] = y1
        seg[sid, 2] = x2
        seg[sid, 3] = y2
        alive[sid] = True
        added_at[sid] = scan
        slot_of[sid] = live
        live_id[live] = sid
        live_box[live, 0] = min(x1, x2)
        live_box[live, 1] = min(y1, y2)
        live_box[live, 2] = max(x1, x2)
        live_box[live, 3] = max(y1, y2)
        live += 1
        view_ids[j] = sid
        added[a] = sid
        a += 1
    return (
        view_ids,
        deleted[:n_del].copy(),
        extended[:n_ext].copy(),
        trimmed[:n_trim].copy(),
        added,
        n + a,
        live,
        n_events,
    )
