"""Chapter 4's network of places scored against reference poses: re-visits, crossings, exit predictions.

Pure functions over ``places.json`` (:mod:`albot1.methods.albot1.places.network`),
the run's estimated poses and the reference poses. The ``places`` metric
(:mod:`albot1.metrics.measures.places`) calls :func:`judge_network` when the
run folder is evaluated, so the mapper never sees the reference poses: it
wrote its claims during the run, and they are scored afterwards, into
``metrics.json`` (``docs/places.md``, "Ground truth").

**Where a visit was.** When the dataset knows its rooms (the synthetic
worlds' ``spaces``), a visit was in the room that holds most of its
reference positions, and two visits were in the same place when their rooms
are the same and they belong to different stays (consecutive visits in one
room are one stay: a false crossing inside a room splits a stay but is no
re-visit). Otherwise (the real logs) a visit's region is the convex hull
of the reference positions it passed through, grown by ``buffer_m``, and two
visits were in the same place when their regions *overlap*: they share at
least ``min_overlap`` of the smaller one's area. A visit never counts the
one just before it as the same place by overlap (they always touch at the
doorway between them). The defaults (1.5 m, 0.4) are calibrated against the
room labels on the synthetic worlds (``docs/places.md``).

* A claimed re-visit (Algorithm 6 or Algorithm 5 line 13) of visit v as
  place P is **true** when v was in the same place as an earlier visit that
  ended up in P.
* A visit in the same place as an earlier visit is a **true re-visit**; it
  is **recognised** when it ended up in the same place as one of those.
  Those not recognised are **missed**. Precision is true claims over
  claims, recall recognised over true re-visits.

**Exits** (when the dataset knows its doorways, as the synthetic worlds do):
a point the mapper placed in its map at scan s is put in the world by the
robot's estimated pose and its reference pose at s (``reference[s] *
inv(estimate[s]) * point``): where the robot believed it was relative to
itself. Each prediction compared at a crossing is then measured against the
true doorway (the one nearest the exit perceived there), aligned and not
aligned; each detected crossing is matched to a true doorway crossing within
``crossing_scans`` scans, the true crossings numbered by the scans the run
saw (:func:`crossings_in_run`: by time, so slices, view spacing and dropout
renumber them as they renumber the run's scans).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.metrics.errors import MetricsError

PLACES_JSON = "places.json"
#: Slack of a crossing's time against the scored scans' times (``trajectory.tum`` keeps nine decimals).
TIME_SLACK_S = 1e-6


def visit_region(reference: FloatArray, first: int, last: int, buffer_m: float) -> Any:
    """The reference positions of scans ``first..last`` as a shapely region (hull grown by ``buffer_m``)."""
    from shapely.geometry import MultiPoint

    pts = np.asarray(reference, dtype=float)[first : last + 1, :2]
    return MultiPoint([tuple(p) for p in pts]).convex_hull.buffer(buffer_m)


def overlap(a: Any, b: Any) -> float:
    """Shared area over the smaller region's area (0 for empty regions)."""
    small = min(a.area, b.area)
    return float(a.intersection(b).area / small) if small > 0 else 0.0


def room_stays(rooms: list[str]) -> list[int]:
    """The number of the stay each scan belongs to: consecutive scans in one room are one stay."""
    stays: list[int] = []
    for k, room in enumerate(rooms):
        stays.append(0 if k == 0 else stays[-1] + (room != rooms[k - 1]))
    return stays


def true_stays(reference: FloatArray, spaces: list[Mapping[str, Any]]) -> tuple[list[str], list[int]]:
    """The route's true room stays over the scored scans: the room and the stay number of each scan.

    Why: recall must count the route's re-visits, not the method's; a method
    that misses doorways has fewer visits but the route re-enters rooms all
    the same. A scan in no room (a doorway) belongs to the stay before it.
    """
    pts = np.asarray(reference, dtype=float)[:, :2]
    rooms: list[str] = []
    for x, y in pts:
        room = next(
            (s["name"] for s in spaces if s["rect"][0] <= x <= s["rect"][2] and s["rect"][1] <= y <= s["rect"][3]),
            "",
        )
        rooms.append(room or (rooms[-1] if rooms else ""))
    return rooms, room_stays(rooms)


def judge_revisits(
    record: Mapping[str, Any],
    reference: FloatArray,
    spaces: list[Mapping[str, Any]] | None = None,
    *,
    buffer_m: float = 1.5,
    min_overlap: float = 0.4,
) -> tuple[dict[str, int | float], list[bool], dict[str, Any]]:
    """Re-visit counters, a truth flag per claimed re-visit (``record["revisits"]`` order) and a summary."""
    visits = record["visits"]
    n = len(reference)
    for v in visits:
        if not (0 <= v["first_scan"] <= v["last_scan"] < n):
            raise MetricsError(
                f"places.json visit {v['id']}: scans {v['first_scan']}..{v['last_scan']} outside the "
                f"{n} reference poses"
            )
    if spaces:
        scan_room, scan_stay = true_stays(reference, spaces)
        stays = [_majority(scan_stay[v["first_scan"] : v["last_scan"] + 1]) for v in visits]
        rooms = [scan_room[scan_stay.index(stay)] for stay in stays]

        def same(a: int, b: int) -> bool:
            return bool(rooms[a]) and rooms[a] == rooms[b] and stays[a] != stays[b]

        rule: dict[str, Any] = {"rule": "rooms", "rooms": rooms}
    else:
        regions = [visit_region(reference, v["first_scan"], v["last_scan"], buffer_m) for v in visits]

        def same(a: int, b: int) -> bool:
            return abs(a - b) > 1 and overlap(regions[a], regions[b]) >= min_overlap

        rule = {"rule": "overlap", "buffer_m": buffer_m, "min_overlap": min_overlap}
    place_of = [v["place"] for v in visits]
    truth = []
    for claim in record["revisits"]:
        vid, place = claim["visit"], claim["place_now"]
        truth.append(any(same(vid, u) for u in range(vid) if place_of[u] == place))
    revisiting = recognised = 0
    per_visit = []
    for vid in range(len(visits)):
        earlier = [u for u in range(vid) if same(vid, u)]
        correct = bool(earlier) and place_of[vid] is not None and any(place_of[u] == place_of[vid] for u in earlier)
        revisiting += bool(earlier)
        recognised += correct
        per_visit.append({"visit": vid, "same_place_as": earlier, "recognised": correct})
    if spaces:
        revisiting, recognised = _route_revisits(reference, visits, spaces, per_visit)
    claims_true = int(sum(truth))
    counters: dict[str, int | float] = {
        "revisits_true": claims_true,
        "revisits_false": len(truth) - claims_true,
        "revisits_missed": revisiting - recognised,
        "revisits_actual": revisiting,
    }
    if truth:
        counters["revisit_precision"] = claims_true / len(truth)
    if revisiting:
        counters["revisit_recall"] = recognised / revisiting
    return counters, truth, {**rule, "visits": per_visit}


def _majority(span: list[int]) -> int:
    """The stay holding most of a visit's scans (the earliest on a tie)."""
    return max(sorted(set(span)), key=span.count)


def _route_revisits(
    reference: FloatArray,
    visits: list[Mapping[str, Any]],
    spaces: list[Mapping[str, Any]],
    per_visit: list[dict[str, Any]],
) -> tuple[int, int]:
    """The route's true re-visits (later stays in a room seen before) and how many of them the method recognised.

    A visit maps to the true stay holding most of its scans; a true re-visit
    stay is recognised when a visit mapped to it is a recognised re-visit.
    """
    scan_room, scan_stay = true_stays(reference, spaces)
    first_stay_of: dict[str, int] = {}
    for room, stay in zip(scan_room, scan_stay, strict=True):
        if room:
            first_stay_of.setdefault(room, stay)
    stay_room = dict(zip(scan_stay, scan_room, strict=True))
    revisit_stays = {stay for stay, room in stay_room.items() if room and first_stay_of[room] != stay}
    hit: set[int] = set()
    for v, judged in zip(visits, per_visit, strict=True):
        stay = _majority(scan_stay[v["first_scan"] : v["last_scan"] + 1])
        if judged["recognised"] and stay in revisit_stays:
            hit.add(stay)
    return len(revisit_stays), len(hit)


def believed_in_world(point: FloatArray, estimate: FloatArray, reference: FloatArray) -> FloatArray:
    """A map point placed in the world as the robot at ``estimate`` (its reference pose) saw it."""
    relative = se2.transform_points(se2.inverse(estimate), np.asarray(point, dtype=float))
    return se2.transform_points(reference, relative)


def _midpoint(segment: Any) -> FloatArray:
    s = np.asarray(segment, dtype=float)
    mid: FloatArray = 0.5 * (s[:2] + s[2:])
    return mid


def crossings_in_run(true_crossings: list[Mapping[str, Any]], timestamps: FloatArray) -> list[int]:
    """The run's scan number of each true doorway crossing it saw: its first scan at or after the crossing's time.

    The dataset numbers its crossings by its own scans (``scan``, the first
    one beyond the threshold, and that scan's time ``t``). A run may have
    seen a selection of them, numbered afresh from 0: a prefix (``[:N]``,
    ``--limit``), every STEP-th (``[::STEP]``), views spaced by ``?views=``
    or a dropout's survivors. The scored scans keep their source times
    through all of these, so the time finds the first scan the run saw on
    the far side, the scan a detector could first notice it at. A crossing
    outside the scored scans' times (after the last) is not in the run.
    """
    t = np.asarray(timestamps, dtype=float)
    if t.size == 0:
        return []
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise MetricsError(
            f"scan {k + 1}: time {t[k + 1]:.6f} s does not follow scan {k}'s {t[k]:.6f} s; the true doorway "
            f"crossings are found among the scans by their times, which must increase"
        )
    out = []
    for k, crossing in enumerate(true_crossings):
        if "t" not in crossing:
            raise MetricsError(f"doorway_crossings[{k}] of the dataset's metadata has no time 't' (s)")
        when = float(crossing["t"])
        if t[0] - TIME_SLACK_S <= when <= t[-1] + TIME_SLACK_S:
            out.append(int(np.searchsorted(t, when - TIME_SLACK_S, side="left")))
    return out


def judge_exits(
    record: Mapping[str, Any],
    timestamps: FloatArray,
    poses: FloatArray,
    reference: FloatArray,
    doorways: list[Mapping[str, Any]],
    true_crossings: list[Mapping[str, Any]],
    *,
    crossing_scans: int = 15,
) -> tuple[dict[str, int | float], dict[str, Any]]:
    """Exit-prediction errors against the true doorways, and detected crossings against the true ones."""
    centres = np.array([[(d["a"][0] + d["b"][0]) / 2, (d["a"][1] + d["b"][1]) / 2] for d in doorways], dtype=float)
    ids = [d["id"] for d in doorways]
    per_exit = []
    for crossing in record["crossings"]:
        pred = crossing.get("prediction")
        if pred is None:
            continue
        s = crossing["scan"]
        est, ref = poses[s], reference[s]
        seen = believed_in_world(_midpoint(crossing["segment"]), est, ref)
        door = int(np.argmin(np.hypot(*(centres - seen).T)))
        errors = {
            key: float(np.hypot(*(believed_in_world(_midpoint(pred[key]), est, ref) - centres[door])))
            for key in ("aligned", "not_aligned")
        }
        per_exit.append(
            {
                "scan": s,
                "exit": crossing["exit"],
                "doorway": ids[door],
                "perceived_error_m": float(np.hypot(*(seen - centres[door]))),
                "aligned_error_m": errors["aligned"],
                "not_aligned_error_m": errors["not_aligned"],
            }
        )
    counters: dict[str, int | float] = {}
    for key in ("aligned", "not_aligned"):
        if per_exit:
            sample = np.array([e[f"{key}_error_m"] for e in per_exit], dtype=float)
            counters[f"exit_prediction_{key}_true_mean_m"] = float(np.mean(sample))
            counters[f"exit_prediction_{key}_true_median_m"] = float(np.median(sample))
    detected = [c["scan"] for c in record["crossings"]]
    truth = crossings_in_run(true_crossings, timestamps)
    used: set[int] = set()
    matched = 0
    for s in detected:
        best = min(
            (t for t in range(len(truth)) if t not in used and abs(truth[t] - s) <= crossing_scans),
            key=lambda t: abs(truth[t] - s),
            default=None,
        )
        if best is not None:
            used.add(best)
            matched += 1
    counters.update(
        crossings_true=matched, crossings_false=len(detected) - matched, crossings_missed=len(truth) - matched
    )
    summary: dict[str, Any] = {"exit_predictions": per_exit, "crossing_scans": crossing_scans}
    if not per_exit:
        summary["exit_predictions_reason"] = no_comparison_reason(record)
    return counters, summary


def no_comparison_reason(record: Mapping[str, Any]) -> str:
    """Why no exit prediction was compared at a crossing, in the terms of the method's own ``places.json``.

    The mapper predicts a place's other exits when it recognises the place
    (``predictions``, one batch per visit) and compares them when that visit
    is left: with the predicted exit nearest the exit crossed, if one lies
    within twice ``exit_link_distance_m`` (farther, the exit is a new way
    out). So nothing is compared when no place was recognised, when the
    places recognised knew no exit but the one entered by, when the run
    ended in a visit with predictions, or when such a visit was left by an
    exit none of them predicted.
    """
    claims = len(record["revisits"])
    if not claims:
        return "no exit prediction compared: no place was recognised (no re-visit claimed), so none was made"
    visits = sorted({int(p["visit"]) for p in record["predictions"]})
    if not visits:
        return (
            f"no exit prediction compared: none was made, as the places of the {claims} re-visit(s) claimed knew no "
            f"exit but the one they were entered by"
        )
    left = {int(c["from_visit"]): c for c in record["crossings"]}
    within = 2.0 * float(record["config"]["exit_link_distance_m"])
    parts = []
    for v in visits:
        if v not in left:
            parts.append(f"the run ended in visit {v} before an exit was crossed")
            continue
        crossed = _midpoint(left[v]["segment"])
        nearest = min(
            float(np.hypot(*(_midpoint(p["aligned"]) - crossed))) for p in record["predictions"] if p["visit"] == v
        )
        parts.append(
            f"visit {v} was left at scan {left[v]['scan']} by an exit {nearest:.2f} m from the nearest prediction "
            f"(beyond {within:g} m the mapper takes it for a new way out)"
        )
    return f"no exit prediction compared: exits were predicted in {len(visits)} visit(s), but " + "; ".join(parts)


def judge_network(
    record: Mapping[str, Any],
    timestamps: FloatArray,
    poses: FloatArray,
    reference: FloatArray,
    dataset: Mapping[str, Any],
) -> dict[str, Any]:
    """Everything above for one run: the ``places`` block of ``metrics.json`` as plain data.

    ``record`` is the run's ``places.json``; ``timestamps``, ``poses`` and
    ``reference`` are the scored scans' (row by row); ``dataset`` is the sequence's
    metadata ``extra`` (doorways and their crossings for the synthetic worlds;
    the exit checks are left out, with the reason, without them). Undefined
    ratios (no claim, no re-visit) are NaN, null in the file.
    """
    poses = se2.as_poses(poses)
    reference = se2.as_poses(reference)
    if not len(poses) == len(reference) == len(timestamps):
        raise MetricsError(
            f"{len(poses)} estimated poses but {len(reference)} reference poses and {len(timestamps)} timestamps"
        )
    counters, truth, summary = judge_revisits(record, reference, list(dataset.get("spaces") or []))
    nan = float("nan")
    block: dict[str, Any] = {
        "units": {"distance": "m", "precision": "fraction", "recall": "fraction"},
        "rule": summary["rule"],
        "rooms": summary.get("rooms"),
        "buffer_m": summary.get("buffer_m"),
        "min_overlap": summary.get("min_overlap"),
        "claims": len(truth),
        "claims_true": truth,
        **{key: counters[key] for key in ("revisits_true", "revisits_false", "revisits_missed", "revisits_actual")},
        "revisit_precision": counters.get("revisit_precision", nan),
        "revisit_recall": counters.get("revisit_recall", nan),
        "visits": summary["visits"],
    }
    doorways = dataset.get("doorways")
    if not doorways:
        return {**block, "exits": None, "exits_reason": "the dataset knows no doorways (exit checks need them)"}
    exit_counters, exit_summary = judge_exits(
        record, timestamps, poses, reference, list(doorways), list(dataset.get("doorway_crossings", []))
    )
    return {
        **block,
        "exits": {
            **exit_summary,
            **{
                f"exit_prediction_{key}_true_{stat}_m": exit_counters.get(f"exit_prediction_{key}_true_{stat}_m", nan)
                for key in ("aligned", "not_aligned")
                for stat in ("mean", "median")
            },
            **{key: exit_counters[key] for key in ("crossings_true", "crossings_false", "crossings_missed")},
        },
    }
