"""albot1-places on small worlds whose network of places can be worked out by hand (thesis 4.1, Algorithms 5-8).

* There and back: room-1 -> room-2 -> room-3 of the six-room plan, then the same way back. Algorithm 5 makes
  a place at each crossing (room-1, room-2, room-3: three places); going back, each exit crossed is the exit
  the place was entered by, which leads to a known place (line 13), so room-2 and then room-1 are recognised
  by the exit, never by structure; room-2's exits are predicted on entering it (Algorithm 7 step 13: the one
  to room-1, the other being the exit just crossed), and that prediction is compared once, when the robot
  crosses into room-1.
* A corridor with a T junction between two rooms: the junction's 2 m opening is no exit ("a gap whose typical
  size is about 1 meter", 4.1.1), so the route crosses two exits and makes two places (the west room, the
  corridor with its branch); the south room is entered but never left, so it is no place yet.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import pytest

from albot1.data.model import Sequence
from albot1.data.synthetic import layouts
from albot1.data.synthetic.floorplan import DoorwaySpec, FloorPlan, Space, build_plan
from albot1.data.synthetic.generate import WorldSpec, generate, stream_frames, world_metadata
from albot1.data.synthetic.route import CONTINUOUS, Route
from albot1.data.synthetic.worlds import OFFICE_ODOMETRY
from albot1.metrics.places import judge_network
from albot1.runs.execute import run_method

#: The single loop's first leg, S in room-1 to A in room-3, then back the same way.
THERE = layouts.PLACES_LOOP[:8]
THERE_AND_BACK = Route(waypoints=THERE + tuple(reversed(THERE[:-1])))


def t_junction_plan() -> FloorPlan:
    """A west room, a corridor 2 m wide with a branch going south from its middle, a south room at its end."""
    spaces = (
        Space("room-w", (0.0, 0.0, 5.0, 6.0)),
        Space("corridor", (5.2, 2.0, 20.0, 4.0)),
        Space("corridor", (11.0, -8.0, 13.0, 2.0)),
        Space("room-s", (8.0, -14.0, 15.0, -8.2)),
    )
    doors = (DoorwaySpec("door-w", (5.1, 3.0), "y", 1.0), DoorwaySpec("door-s", (12.0, -8.1), "x", 1.0))
    furniture = (
        (0.5, 0.5, 2.5, 1.5),
        (3.3, 4.0, 4.0, 5.5),
        layouts.askew((1.0, 4.5), (1.0, 0.4), 40.0),
        (9.0, -13.5, 11.0, -12.8),
        (14.0, -11.0, 14.6, -9.0),
        layouts.askew((10.0, -10.0), (1.0, 0.4), -30.0),
    )
    return build_plan("t-junction", spaces, doors, furniture)


T_ROUTE = Route(waypoints=((2.0, 2.5), (4.0, 3.0), (8.0, 3.0), (12.0, 3.0), (12.0, -6.0), (12.0, -11.0)))


def run(name: str, plan: Callable[[], FloorPlan], route: Route) -> dict:
    """The run's ``places.json`` with the places metric's judgement (rooms of the visits, true crossings)."""
    spec = WorldSpec(name, name, plan, lambda: route, CONTINUOUS, odometry=OFFICE_ODOMETRY, seed=141)
    data = generate(spec)
    sequence = Sequence(name, functools.partial(stream_frames, data), world_metadata(data), scan_count=data.scans)
    result = run_method("albot1-places", sequence, preset="thesis")
    places = result.files["places.json"]
    judged = judge_network(places, result.timestamps, result.poses, result.reference, sequence.metadata.extra)
    return {"places": places, "judged": judged, "counters": result.counters}


@pytest.mark.slow
def test_a_route_driven_back_re_enters_each_place_by_the_exit_it_left_by() -> None:
    out = run("there-and-back", layouts.places_plan, THERE_AND_BACK)
    places, judged = out["places"], out["judged"]
    assert judged["rooms"] == ["room-1", "room-2", "room-3", "room-2", "room-1"]
    assert (judged["exits"]["crossings_true"], judged["exits"]["crossings_false"]) == (4, 0)
    assert [(c["from_place"], c["to_place"]) for c in places["crossings"]] == [(0, None), (1, None), (2, 1), (1, 0)]
    assert [(r["visit"], r["place_now"], r["how"]) for r in places["revisits"]] == [(3, 1, "exit"), (4, 0, "exit")]
    assert len(places["places"]) == 3 and [(x["place"], x["to_place"]) for x in places["links"]] == [(0, 1), (1, 2)]
    # on entering room-2 again: its exit to room-1 predicted, compared when that exit is crossed
    room_2_to_1 = places["links"][0]["to_exit"]
    assert [(p["place"], p["exit"]) for p in places["predictions"]] == [(1, room_2_to_1)]
    compared = [c["prediction"]["exit"] for c in places["crossings"] if c["prediction"] is not None]
    assert compared == [room_2_to_1]
    assert (judged["revisits_true"], judged["revisits_false"], judged["revisits_missed"]) == (2, 0, 0)


@pytest.mark.slow
def test_a_corridor_junction_is_no_exit() -> None:
    out = run("t-junction", t_junction_plan, T_ROUTE)
    places, judged = out["places"], out["judged"]
    assert judged["rooms"] == ["room-w", "corridor", "room-s"]
    assert (judged["exits"]["crossings_true"], judged["exits"]["crossings_false"]) == (2, 0)
    assert out["counters"]["places_created"] == 2 and len(places["visits"]) == 3
    assert places["revisits"] == [] and places["predictions"] == []
    assert [(x["place"], x["to_place"]) for x in places["links"]] == [(0, 1)]
