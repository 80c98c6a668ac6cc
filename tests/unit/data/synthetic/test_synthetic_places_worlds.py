"""The chapter-4 worlds: six rooms in a ring, start points, laps, the double loop, askew furniture."""

from __future__ import annotations

import numpy as np
import pytest

from albot1.data.errors import DatasetNotFoundError
from albot1.data.open import open_sequence
from albot1.data.synthetic import layouts, worlds
from albot1.data.synthetic.errors import SyntheticWorldError, WorldOptionError
from albot1.data.synthetic.route import Route, start_at

RING = ["door-1-2", "door-2-3", "door-3-4", "door-4-5", "door-5-6", "door-6-1"]


def rooms_visited(data: worlds.WorldData) -> list[str]:
    return [c.to_space for c in data.crossings]


def test_the_single_loop_crosses_the_six_doorways_once_each_and_closes() -> None:
    data = worlds.world_data("synthetic-places-loop")
    assert [c.doorway for c in data.crossings] == RING
    assert rooms_visited(data) == ["room-2", "room-3", "room-4", "room-5", "room-6", "room-1"]
    np.testing.assert_array_equal(data.reference[0], data.reference[-1])
    assert data.plan.space_at(*data.reference[0, :2]) == "room-1"
    assert 45.0 < data.route_length < 55.0


@pytest.mark.parametrize(("start", "room", "first_door"), [(0, "room-1", 0), (1, "room-3", 2), (2, "room-5", 4)])
def test_each_start_point_drives_the_same_loop_from_another_room(start: int, room: str, first_door: int) -> None:
    data = worlds.world_data("synthetic-places-loop", start=start)
    assert data.plan.space_at(*data.reference[0, :2]) == room
    assert [c.doorway for c in data.crossings] == RING[first_door:] + RING[:first_door]
    np.testing.assert_array_equal(data.reference[0], data.reference[-1])
    assert data.route_length == pytest.approx(worlds.world_data("synthetic-places-loop").route_length)
    seq = open_sequence(f"synthetic-places-loop?start={start}")
    assert seq.name == f"synthetic-places-loop?start={start}"
    assert next(iter(seq)).reference == pytest.approx(data.reference[0])


def test_laps_drive_the_loop_again() -> None:
    one, two = worlds.world_data("synthetic-places-loop"), worlds.world_data("synthetic-places-loop", laps=2)
    assert two.scans == 2 * one.scans - 1
    assert [c.doorway for c in two.crossings] == RING + RING
    assert open_sequence("synthetic-places-loop?laps=2").name == "synthetic-places-loop?laps=2"


def test_the_double_loop_enters_room_5_from_the_north_the_second_time() -> None:
    data = worlds.world_data("synthetic-places-double-loop")
    assert [c.doorway for c in data.crossings] == [*RING, "door-1-2", "door-2-5", "door-5-6", "door-6-1"]
    assert [(c.from_space, c.to_space) for c in data.crossings if c.doorway == "door-2-5"] == [("room-2", "room-5")]
    np.testing.assert_array_equal(data.reference[0], data.reference[-1])


def test_rooms_differ_in_size_and_each_has_a_piece_of_furniture_askew() -> None:
    sizes = {
        (round(x1 - x0, 1), round(y1 - y0, 1))
        for _, (x0, y0, x1, y1) in ((s.name, s.rect) for s in layouts.PLACES_SPACES)
    }
    assert len(sizes) == 6
    askew = [f for f in layouts.PLACES_FURNITURE if isinstance(f[0], tuple)]
    assert len(askew) == 6
    plan = worlds.world_data("synthetic-places-loop").plan
    walls = plan.walls
    angles = np.degrees(np.arctan2(walls[:, 3] - walls[:, 1], walls[:, 2] - walls[:, 0])) % 90.0
    assert np.count_nonzero((angles > 1.0) & (angles < 89.0)) == 6 * 4  # the askew pieces' sides


def test_metadata_names_the_rooms() -> None:
    extra = worlds.load_world("synthetic-places-loop").metadata.extra
    assert {s["name"] for s in extra["spaces"]} == {f"room-{k}" for k in range(1, 7)}
    assert len(extra["doorways"]) == 6 and len(extra["doorway_crossings"]) == 6


def test_options_a_world_does_not_take_are_named() -> None:
    with pytest.raises(WorldOptionError, match="has one start point; it takes no start option") as info:
        worlds.world_data("synthetic-office-loop", start=1)
    assert isinstance(info.value, DatasetNotFoundError)
    with pytest.raises(WorldOptionError, match=r"start=3; expected an integer 0\.\.2"):
        worlds.world_data("synthetic-places-loop", start=3)
    with pytest.raises(WorldOptionError, match="laps=0; expected a positive integer"):
        worlds.world_data("synthetic-places-loop", laps=0)
    with pytest.raises(WorldOptionError, match="its route is not a closed loop"):
        worlds.world_data("synthetic-corridor", laps=2)
    with pytest.raises(WorldOptionError, match="unknown loader option.s. seed; expected start or laps"):
        open_sequence("synthetic-places-loop?seed=3")


def test_start_at_rotates_a_closed_route_and_refuses_an_open_one() -> None:
    route = Route(((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 0.0)), closed=True)
    assert start_at(route, 1).waypoints == ((1.0, 0.0), (1.0, 1.0), (0.0, 0.0), (1.0, 0.0))
    assert start_at(route, 0) is route
    with pytest.raises(SyntheticWorldError, match="start waypoint 3 is not one of the loop's 0..2"):
        start_at(route, 3)
    with pytest.raises(SyntheticWorldError, match="only a closed route"):
        start_at(Route(((0.0, 0.0), (1.0, 0.0))), 0)
