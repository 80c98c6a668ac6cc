"""Floor plans: walls from free space, doorways as wall gaps, furniture, and exact doorway crossings."""

from __future__ import annotations

import numpy as np
import pytest

from albot1.data.synthetic.errors import SyntheticWorldError
from albot1.data.synthetic.floorplan import (
    DoorwayCrossing,
    DoorwaySpec,
    FloorPlan,
    Space,
    build_plan,
    check_route,
    doorway_crossings,
)


def edges(walls: np.ndarray) -> set[frozenset[tuple[float, float]]]:
    """Wall segments as undirected, rounded edges (order- and direction-free comparison)."""
    return {
        frozenset({(round(float(a), 9), round(float(b), 9)), (round(float(c), 9), round(float(d), 9))})
        for a, b, c, d in walls
    }


def two_rooms():
    """Room x 0..4 and hall x 4.2..10 (both y -2..2) joined by a 1 m doorway in the wall at x = 4..4.2."""
    return build_plan(
        "two",
        [Space("room", (0.0, -2.0, 4.0, 2.0)), Space("hall", (4.2, -2.0, 10.0, 2.0))],
        [DoorwaySpec("d1", (4.1, 0.0), "y", 1.0)],
    )


def test_a_single_room_has_its_four_walls() -> None:
    plan = build_plan("box", [Space("room", (0.0, 0.0, 5.0, 3.0))])
    assert edges(plan.walls) == edges(np.array([[0, 0, 5, 0], [5, 0, 5, 3], [5, 3, 0, 3], [0, 3, 0, 0]]))
    assert plan.doorways == ()


def test_corridor_pieces_with_one_name_merge_without_inner_walls() -> None:
    plan = build_plan("L", [Space("corridor", (0.0, 0.0, 10.0, 2.0)), Space("corridor", (0.0, 0.0, 2.0, 8.0))])
    assert edges(plan.walls) == edges(
        np.array([[0, 0, 10, 0], [10, 0, 10, 2], [10, 2, 2, 2], [2, 2, 2, 8], [2, 8, 0, 8], [0, 8, 0, 0]])
    )


def test_a_doorway_is_a_gap_with_jambs_through_the_wall() -> None:
    plan = two_rooms()
    expected = np.array(
        [
            [0, -2, 4, -2],
            [4, -2, 4, -0.5],
            [4, -0.5, 4.2, -0.5],
            [4.2, -0.5, 4.2, -2],
            [4.2, -2, 10, -2],
            [10, -2, 10, 2],
            [10, 2, 4.2, 2],
            [4.2, 2, 4.2, 0.5],
            [4.2, 0.5, 4, 0.5],
            [4, 0.5, 4, 2],
            [4, 2, 0, 2],
            [0, 2, 0, -2],
        ]
    )
    assert edges(plan.walls) == edges(expected)
    (door,) = plan.doorways
    assert door.id == "d1"
    assert door.a == (4.1, -0.5) and door.b == (4.1, 0.5)
    assert door.width == pytest.approx(1.0)
    assert door.centre == (4.1, 0.0)
    assert door.spaces == ("room", "hall")  # room is left of a -> b (pointing +y)
    assert plan.doorway("d1") is door
    assert plan.space_at(1.0, 0.0) == "room" and plan.space_at(5.0, 1.0) == "hall"
    assert plan.space_at(4.1, 0.0) is None


def test_horizontal_wall_doorway_sides() -> None:
    plan = build_plan(
        "v",
        [Space("south", (0.0, 0.0, 4.0, 3.0)), Space("north", (0.0, 3.2, 4.0, 6.0))],
        [DoorwaySpec("n", (2.0, 3.1), "x", 0.9)],
    )
    (door,) = plan.doorways
    assert door.a == (1.55, 3.1) and door.b == (2.45, 3.1)
    assert door.spaces == ("north", "south")


def test_furniture_adds_a_closed_outline() -> None:
    plain = build_plan("room", [Space("room", (0.0, 0.0, 6.0, 6.0))])
    furnished = build_plan("room", [Space("room", (0.0, 0.0, 6.0, 6.0))], obstacles=[(2.0, 2.0, 3.0, 2.5)])
    extra = edges(furnished.walls) - edges(plain.walls)
    assert extra == edges(np.array([[2, 2, 3, 2], [3, 2, 3, 2.5], [3, 2.5, 2, 2.5], [2, 2.5, 2, 2]]))
    assert furnished.obstacles == ((2.0, 2.0, 3.0, 2.5),)
    assert furnished.free_space().area == pytest.approx(36.0 - 0.5)


@pytest.mark.parametrize(
    ("spaces", "doors", "message"),
    [
        ([Space("a", (0, 0, 4, 4))], [DoorwaySpec("x", (9.0, 9.0), "y")], "does not open into a space"),
        ([Space("a", (0, 0, 4, 4))], [DoorwaySpec("x", (2.0, 2.0), "y")], "joins space 'a' to itself"),
        (
            [Space("a", (0, 0, 4, 4)), Space("b", (4.2, 0, 8, 4))],
            [DoorwaySpec("x", (4.1, 2.0), "y"), DoorwaySpec("x", (4.1, 3.0), "y")],
            "unique",
        ),
        (
            [Space("a", (0, 0, 4, 4)), Space("b", (4.2, 0, 8, 4))],
            [DoorwaySpec("x", (4.1, 2.0), "z")],  # type: ignore[arg-type]
            "'x' or 'y'",
        ),
        (
            [Space("a", (0, 0, 4, 4)), Space("b", (4.2, 0, 8, 4))],
            [DoorwaySpec("x", (4.1, 2.0), "y", 0.0)],
            "positive width",
        ),
        ([Space("a", (4, 0, 0, 4))], [], "xmin < xmax"),
    ],
)
def test_bad_plans_are_rejected_naming_the_element(spaces, doors, message) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(SyntheticWorldError, match=message):
        build_plan("bad", spaces, doors)


def test_unknown_doorway_lists_the_doorways() -> None:
    with pytest.raises(SyntheticWorldError, match="doorways: d1"):
        two_rooms().doorway("d9")


def _poses(*xy: tuple[float, float]) -> np.ndarray:
    return np.array([[x, y, 0.0] for x, y in xy])


def _crossings(plan: FloorPlan, *xy: tuple[float, float]) -> list[DoorwayCrossing]:
    """The crossings of the route through ``xy``, one scan every 0.5 s from t = 10 s."""
    return doorway_crossings(plan, _poses(*xy), 10.0 + 0.5 * np.arange(len(xy)))


def test_a_crossing_is_found_exactly_on_the_threshold() -> None:
    plan = two_rooms()
    (crossing,) = _crossings(plan, (2.0, 0.0), (3.95, 0.1), (4.35, 0.3), (6.0, 0.3))
    assert crossing.scan == 2 and crossing.time == 11.0  # the first scan beyond the threshold, and its time
    assert crossing.doorway == "d1"
    assert (crossing.from_space, crossing.to_space) == ("room", "hall")
    assert crossing.position[0] == pytest.approx(4.1, abs=1e-12)
    assert crossing.position[1] == pytest.approx(0.1 + 0.2 * 0.15 / 0.4, abs=1e-12)
    assert crossing.as_dict() == {
        "scan": 2,
        "t": 11.0,
        "x": crossing.position[0],
        "y": crossing.position[1],
        "doorway": "d1",
        "from": "room",
        "to": "hall",
    }


def test_there_and_back_gives_two_crossings_in_route_order() -> None:
    got = _crossings(two_rooms(), (3.0, 0.0), (5.0, 0.0), (6.0, 0.0), (3.5, -0.2))
    assert [(c.scan, c.from_space, c.to_space) for c in got] == [(1, "room", "hall"), (3, "hall", "room")]


def test_a_pose_on_the_threshold_is_one_crossing_at_that_scan() -> None:
    plan = two_rooms()
    forward = _crossings(plan, (3.0, 0.0), (4.1, 0.0), (5.0, 0.0))
    backward = _crossings(plan, (5.0, 0.0), (4.1, 0.0), (3.0, 0.0))
    assert [(c.scan, c.position) for c in forward] == [(1, (4.1, 0.0))]
    assert [(c.scan, c.position, c.to_space) for c in backward] == [(1, (4.1, 0.0), "room")]


def test_touching_a_threshold_and_turning_back_is_not_a_crossing() -> None:
    assert _crossings(two_rooms(), (3.0, 0.0), (4.1, 0.0), (4.1, 0.0), (3.0, 0.2)) == []


def test_crossing_the_wall_line_outside_the_doorway_is_not_a_doorway_crossing() -> None:
    assert _crossings(two_rooms(), (3.0, 1.0), (5.0, 1.0)) == []
    assert _crossings(two_rooms(), (3.0, 0.0)) == []


def test_routes_must_stay_on_the_free_floor_with_clearance() -> None:
    plan = two_rooms()
    check_route(plan, [(1.0, 0.0), (8.0, 0.0), (8.0, 1.5)], clearance=0.25)  # through the doorway: fine
    with pytest.raises(SyntheticWorldError, match="route leg 1 from"):
        check_route(plan, [(1.0, 0.0), (3.0, 1.0), (8.0, 1.0)])  # through the wall beside the doorway
    with pytest.raises(SyntheticWorldError, match="within 0.3 m of a wall"):
        check_route(plan, [(1.0, 0.3), (8.0, 0.3)], clearance=0.3)  # 0.2 m from the jamb
    check_route(plan, [(1.0, 0.3), (8.0, 0.3)], clearance=0.15)
