"""The network of places as files: ``places.json`` (everything) and ``places.graphml`` (the graph).

Coordinates leave in the REP-103 convention of the run's other outputs: a
map-frame segment or point in the run's map frame (as ``map.geojson``), a
place's own surfaces and exits in its own frame with x along the heading the
robot had when it entered the place (its frame's origin). ``places.json``
holds, in order:

* ``places``: every place ever created, ``merged_into`` naming the place a
  merged one became; a live place's ``surfaces`` and ``exits`` (own frame;
  ``through`` flags the surfaces seen only through one of its exits),
  each exit with where it leads (``leads_to`` place, ``leads_exit``) and where
  it was first seen in the map (``learned_map``); ``frame_in_map`` (where its
  frame lay in the map when created), ``extent_m`` (:func:`extent`) and
  ``centre_map`` (the centre of that box placed in the map, where the
  network plot draws it);
* ``links``: one per pair of linked exits;
* ``visits``: each stay, its scans and place (null for a final visit never
  recognised or closed), the exits it came in and left by;
* ``revisits``: every claimed re-visit (``how``: ``structure`` for Algorithm 6,
  ``exit`` for Algorithm 5 line 13), with the scan and the place;
* ``crossings``: every exit crossed, with the nearest predicted exit and the
  aligned / not-aligned midpoint distances of Figure 4.8;
* ``predictions``: every exit brought into the map (Figure 4.7).

The claims are judged against the reference poses when the run is evaluated,
by the ``places`` metric (:mod:`albot1.metrics.measures.places`,
``docs/places.md``); this file stays as the mapper wrote it.
"""

from __future__ import annotations

import importlib
from typing import Any

import numpy as np
from pydantic import BaseModel

from albot1.geometry.se2 import Pose, compose_pose
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.perception.frames import thesis_to_rep_pose, thesis_to_rep_segments
from albot1.methods.albot1.places.memory import Place, PlaceNetwork

PLACES_JSON = "places.json"
PLACES_GRAPHML = "places.graphml"


def _seg(segment: FloatArray) -> list[float]:
    return [float(v) for v in thesis_to_rep_segments(np.asarray(segment, dtype=float))[0]]


def _segs(segments: FloatArray) -> list[list[float]]:
    listed: list[list[float]] = thesis_to_rep_segments(np.asarray(segments, dtype=float).reshape(-1, 4)).tolist()
    return listed


def _pose(pose: Pose) -> list[float]:
    return [float(v) for v in thesis_to_rep_pose(pose)]


def _point(x: float, y: float) -> list[float]:
    return [float(y), float(-x)]


def extent(place: Place) -> tuple[float, tuple[float, float]]:
    """A place's size (m) and centre (own thesis frame): half the diagonal of its own surfaces' midpoints' box.

    Own surfaces only (not those seen through its exits), and their
    midpoints, not their ends: a wall the perceptual map extended along
    several rooms would otherwise make every place as large as the building.
    """
    own = place.surfaces[~place.through] if len(place.through) == len(place.surfaces) else place.surfaces
    if len(own) == 0:
        return 0.0, (0.0, 0.0)
    mids = 0.5 * (own[:, :2] + own[:, 2:])
    lo, hi = mids.min(axis=0), mids.max(axis=0)
    return float(0.5 * np.hypot(*(hi - lo))), (float(0.5 * (lo[0] + hi[0])), float(0.5 * (lo[1] + hi[1])))


def places_record(
    network: PlaceNetwork,
    *,
    crossings: list[dict[str, Any]],
    revisits: list[dict[str, Any]],
    predictions: list[dict[str, Any]],
    scans: int,
    config: BaseModel,
) -> dict[str, Any]:
    """The ``places.json`` document (JSON-able)."""
    places = []
    for place in network.places:
        radius, centre = extent(place)
        centre_map = compose_pose(place.frame_map, (centre[0], centre[1], 0.0))
        places.append(
            {
                "id": place.id,
                "created_scan": place.created_scan,
                "merged_into": None if place.merged_into is None else network.find(place.id),
                "merged_scan": place.merged_scan,
                "visits": list(place.visits),
                "frame_in_map": _pose(place.frame_map),
                "extent_m": radius,
                "centre_map": _point(centre_map[0], centre_map[1]),
                "surfaces": _segs(place.surfaces),
                "through": place.through.tolist(),
                "exits": [
                    {
                        "id": e.id,
                        "segment": _seg(e.segment),
                        "learned_map": _seg(e.learned_map),
                        "scan": e.scan,
                        "leads_to": None if e.leads_to is None else network.find(e.leads_to),
                        "leads_exit": None if e.leads_exit is None else network.exit_id(e.leads_exit),
                    }
                    for e in place.exits
                ],
            }
        )
    links, seen = [], set()
    for place in network.live_places():
        for e in place.exits:
            target = network.leads(place.id, e.id)
            if target is None:
                continue
            pair = frozenset({(place.id, e.id), target})
            if pair in seen:
                continue
            seen.add(pair)
            links.append({"place": place.id, "exit": e.id, "to_place": target[0], "to_exit": target[1]})
    visits = [
        {
            "id": v.id,
            "place": None if v.place is None else network.find(v.place),
            "first_scan": v.first_scan,
            "last_scan": v.last_scan if v.last_scan is not None else scans - 1,
            "closed": v.last_scan is not None,
            "entered_by": None if v.entry_exit is None else network.exit_id(v.entry_exit),
            "left_by": None if v.left_by is None else network.exit_id(v.left_by),
        }
        for v in network.visits
    ]
    return {
        "frame": "REP-103; map-frame values as map.geojson, own-frame values with x along the place's entry heading",
        "config": {k: v for k, v in config.model_dump(mode="json").items() if k.startswith(_PLACE_FIELDS)},
        "places": places,
        "links": links,
        "visits": visits,
        "revisits": [_revisit(r, network) for r in revisits],
        "crossings": [_crossing(c, network) for c in crossings],
        "predictions": [
            {**p, "aligned": _seg(p["aligned"]), "not_aligned": _seg(p["not_aligned"])} for p in predictions
        ],
    }


_PLACE_FIELDS = ("exit_", "crossing_", "place_", "match_", "revisit_", "recognition_exit_")


def _revisit(record: dict[str, Any], network: PlaceNetwork) -> dict[str, Any]:
    out = dict(record)
    out["place_now"] = network.find(record["place"])
    return out


def _crossing(record: dict[str, Any], network: PlaceNetwork) -> dict[str, Any]:
    out = dict(record)
    out["segment"] = _seg(record["segment"])
    out["robot"] = _pose(record["robot"])
    out["exit"] = network.exit_id(record["exit"])
    out["from_place"] = network.find(record["from_place"])
    out["to_place"] = None if record["to_place"] is None else network.find(record["to_place"])
    pred = record["prediction"]
    if pred is not None:
        out["prediction"] = {**pred, "aligned": _seg(pred["aligned"]), "not_aligned": _seg(pred["not_aligned"])}
    return out


#: The library :func:`graphml` writes with: imported when it is first needed, not with this module.
GRAPH_LIBRARY = "networkx"


def load_graph_library() -> None:
    """Import :data:`GRAPH_LIBRARY` now, so that writing ``places.graphml`` at the end of a run does not.

    Why: the import (0.1-0.4 s) is start-up, not output; the mapper's
    warm-up calls this before the timed loop, so ``finish_s`` times only the
    writing, and the bench's forkserver, which runs every warm-up before it
    forks a cell, imports it once for all cells. This module itself does not
    import it, so that importing the mapper (test collection, methods that
    never write the network) does not pay for it.
    """
    importlib.import_module(GRAPH_LIBRARY)


def graphml(record: dict[str, Any]) -> str:
    """The live places and their links as GraphML (networkx), node and edge attributes flat."""
    import networkx as nx

    graph = nx.MultiGraph(name="albot1 network of places")
    for place in record["places"]:
        if place["merged_into"] is not None:
            continue
        graph.add_node(
            f"P{place['id']}",
            place=place["id"],
            surfaces=len(place["surfaces"]),
            exits=len(place["exits"]),
            visits=len(place["visits"]),
            extent_m=place["extent_m"],
            x=place["centre_map"][0],
            y=place["centre_map"][1],
            created_scan=place["created_scan"],
        )
    for link in record["links"]:
        graph.add_edge(f"P{link['place']}", f"P{link['to_place']}", exit=link["exit"], to_exit=link["to_exit"])
    return "\n".join(nx.generate_graphml(graph)) + "\n"


def network_files(network: PlaceNetwork, **record_args: Any) -> dict[str, Any]:
    """``places.json`` (a JSON document) and ``places.graphml`` (text) for the run folder."""
    record = places_record(network, **record_args)
    return {PLACES_JSON: record, PLACES_GRAPHML: graphml(record)}
