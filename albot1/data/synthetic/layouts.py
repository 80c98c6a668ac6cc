"""The floor plans and routes of the embedded worlds (metres, REP-103 world frame).

The office is modelled on the kind of building the thesis's robot lived in
(level one of the AUT Tower, Figure 3.3): a corridor ring 2 m wide around a
24 x 16 m block, rooms inside and outside the ring reached through 0.9-1.0 m
doorways, furniture in the rooms, and alcoves in the corridor walls. The
route visits rooms by driving *through* them wherever a room has two
doorways (office-sw, lab), so each visit yields an entry and an exit
crossing with few half turns, and it closes on itself in the west corridor:

    S(1,9) south -> (1,5) east through office-sw -> (5,1) east along the
    south corridor -> (23,1) north -> kitchen and back -> (23,15) west ->
    south through the lab -> west corridor -> S

About 79 m long; at 1 m / 45 deg steps that is 106 views, the count of the
thesis's Experiment 3. The corridor world is the thesis's corridor "C"
(Section 3.2.1): 60 m long and 2 m wide, with nothing on its walls.
"""

from __future__ import annotations

import math

from albot1.data.synthetic.floorplan import DoorwaySpec, FloorPlan, Obstacle, Rect, Space, build_plan
from albot1.data.synthetic.route import Route
from albot1.geometry import se2

OFFICE_SPACES: tuple[Space, ...] = (
    Space("corridor", (0.0, 0.0, 24.0, 2.0)),
    Space("corridor", (0.0, 14.0, 24.0, 16.0)),
    Space("corridor", (0.0, 0.0, 2.0, 16.0)),
    Space("corridor", (22.0, 0.0, 24.0, 16.0)),
    Space("corridor", (8.0, 16.0, 9.5, 16.6)),  # alcove, north wall
    Space("corridor", (-0.6, 6.0, 0.0, 7.5)),  # alcove, west wall
    Space("office-sw", (2.2, 2.2, 11.9, 7.9)),
    Space("office-se", (12.1, 2.2, 21.8, 7.9)),
    Space("lab", (2.2, 8.1, 21.8, 13.8)),
    Space("meeting", (14.0, -5.2, 20.0, -0.2)),
    Space("kitchen", (24.2, 10.0, 29.0, 15.0)),
)

OFFICE_DOORWAYS: tuple[DoorwaySpec, ...] = (
    DoorwaySpec("office-sw-west", (2.1, 5.0), "y", 0.9),
    DoorwaySpec("office-sw-south", (5.0, 2.1), "x", 0.9),
    DoorwaySpec("office-sw-se", (12.0, 6.5), "y", 0.9),
    DoorwaySpec("office-se-east", (21.9, 5.0), "y", 1.0),
    DoorwaySpec("lab-north", (17.0, 13.9), "x", 1.0),
    DoorwaySpec("lab-west", (2.1, 11.0), "y", 1.0),
    DoorwaySpec("meeting", (17.0, -0.1), "x", 1.0),
    DoorwaySpec("kitchen", (24.1, 12.5), "y", 0.9),
)

OFFICE_FURNITURE: tuple[Rect, ...] = (
    (8.0, 5.6, 10.5, 6.4),  # office-sw desks and cabinet
    (3.0, 6.8, 4.6, 7.5),
    (10.9, 2.6, 11.6, 4.6),
    (13.5, 3.0, 15.5, 3.8),  # office-se desks and a pillar
    (17.0, 6.0, 19.5, 6.8),
    (20.0, 3.0, 20.5, 3.5),
    (4.5, 8.8, 6.5, 9.6),  # lab benches and a pillar
    (9.5, 8.8, 11.5, 9.6),
    (12.5, 12.4, 14.5, 13.2),
    (7.0, 12.6, 7.6, 13.2),
    (16.0, -3.5, 18.0, -2.5),  # meeting table
    (27.8, 10.4, 28.8, 14.6),  # kitchen counter
)


def office_plan() -> FloorPlan:
    return build_plan("office", OFFICE_SPACES, OFFICE_DOORWAYS, OFFICE_FURNITURE)


def office_loop() -> Route:
    return Route(
        waypoints=(
            (1.0, 9.0),
            (1.0, 5.0),
            (5.0, 5.0),
            (5.0, 1.0),
            (23.0, 1.0),
            (23.0, 12.5),
            (26.5, 12.5),
            (23.0, 12.5),
            (23.0, 15.0),
            (17.0, 15.0),
            (17.0, 11.0),
            (1.0, 11.0),
            (1.0, 9.0),
        ),
        closed=True,
        start_heading=-math.pi / 2,
    )


CORRIDOR_LENGTH = 60.0


def corridor_plan() -> FloorPlan:
    return build_plan("corridor", (Space("corridor", (0.0, -1.0, CORRIDOR_LENGTH, 1.0)),))


def corridor_route() -> Route:
    return Route(waypoints=((2.0, 0.0), (55.0, 0.0)))


# --- Six rooms joined by doorways (thesis chapter 4, Experiments 4.2.1-4.2.3) -------------------------------------
#
# Six rooms of different sizes (4.8-7 m deep, 5-8 m wide) and furniture, in two rows, joined in a ring by six
# 1 m doorways: room-1 (north-west) -> room-2 -> room-3 (north-east) -> room-4 (south-east) -> room-5 ->
# room-6 (south-west) -> room-1. No two rooms have the same shape, and each has one piece of furniture
# standing askew at its own angle: a room is told from another by its structure alone (4.1.2), and
# rectangular rooms with square-set furniture would all look alike. The double-loop plan adds a seventh doorway
# between room-2 and room-5, so a second loop can enter room-5 from the north, a direction the first loop
# never saw it from (4.2.2).

PLACES_SPACES: tuple[Space, ...] = (
    Space("room-1", (0.0, 6.2, 6.0, 12.2)),
    Space("room-2", (6.2, 6.2, 14.2, 11.0)),
    Space("room-3", (14.4, 6.2, 20.0, 13.0)),
    Space("room-4", (12.2, -1.0, 20.0, 6.0)),
    Space("room-5", (5.2, 1.0, 12.0, 6.0)),
    Space("room-6", (0.0, 0.0, 5.0, 6.0)),
)

PLACES_DOORWAYS: tuple[DoorwaySpec, ...] = (
    DoorwaySpec("door-1-2", (6.1, 9.0), "y", 1.0),
    DoorwaySpec("door-2-3", (14.3, 8.0), "y", 1.0),
    DoorwaySpec("door-3-4", (18.0, 6.1), "x", 1.0),
    DoorwaySpec("door-4-5", (12.1, 3.0), "y", 1.0),
    DoorwaySpec("door-5-6", (5.1, 4.0), "y", 1.0),
    DoorwaySpec("door-6-1", (2.5, 6.1), "x", 1.0),
)

#: The double loop's extra doorway: room-2 to room-5 through their shared wall.
PLACES_DOOR_2_5 = DoorwaySpec("door-2-5", (9.3, 6.1), "x", 1.0)


def askew(centre: tuple[float, float], size: tuple[float, float], degrees: float) -> tuple[tuple[float, float], ...]:
    """The corners of a ``size`` (length, depth) box centred at ``centre``, turned ``degrees`` counter-clockwise."""
    frame = (centre[0], centre[1], math.radians(degrees))
    half = (size[0] / 2.0, size[1] / 2.0)
    corners = ((-half[0], -half[1]), (half[0], -half[1]), (half[0], half[1]), (-half[0], half[1]))
    return tuple(se2.compose_pose(frame, (x, y, 0.0))[:2] for x, y in corners)


PLACES_FURNITURE: tuple[Obstacle, ...] = (
    (0.8, 10.8, 2.8, 11.6),  # room-1: desk, cabinet, pillar
    (4.6, 7.0, 5.6, 7.6),
    (3.6, 7.9, 4.1, 8.4),
    (7.5, 10.0, 11.5, 10.5),  # room-2: long bench and two boxes
    (8.0, 6.8, 8.6, 7.4),
    (12.2, 8.6, 13.4, 9.2),
    (15.0, 11.6, 16.8, 12.5),  # room-3: cabinet, shelf, pillar
    (18.6, 9.0, 19.5, 12.0),
    (16.5, 7.4, 17.0, 7.9),
    (14.5, 1.0, 17.0, 2.5),  # room-4: table, cabinet, box
    (19.2, -0.6, 19.7, 1.6),
    (12.8, -0.5, 13.6, 0.2),
    (6.0, 1.5, 7.5, 2.2),  # room-5: two desks and a pillar
    (9.8, 4.6, 11.3, 5.3),
    (8.8, 2.0, 9.3, 2.5),
    (0.5, 0.5, 2.5, 1.5),  # room-6: desk and shelf
    (3.3, 1.5, 4.0, 3.3),
    askew((4.6, 10.8), (1.2, 0.5), 25.0),  # one piece askew per room, each at its own angle
    askew((12.8, 6.9), (1.0, 0.4), -35.0),
    askew((19.3, 7.2), (1.0, 0.4), 50.0),
    askew((15.8, 4.6), (1.4, 0.5), 20.0),
    askew((6.6, 5.3), (1.0, 0.4), -20.0),
    askew((1.0, 4.2), (1.0, 0.4), 40.0),
)

#: One lap of the single loop, from S in room-1 clockwise through the six doorways back to S.
PLACES_LOOP: tuple[tuple[float, float], ...] = (
    (2.5, 10.0),  # S, room-1
    (4.5, 9.0),
    (7.0, 9.0),  # through door-1-2
    (10.0, 9.0),
    (10.0, 8.0),
    (15.2, 8.0),  # through door-2-3
    (16.0, 10.0),
    (18.0, 9.0),  # A, room-3
    (18.0, 5.0),  # through door-3-4
    (18.0, 0.3),
    (14.0, 0.4),
    (13.2, 3.0),
    (11.2, 3.0),  # through door-4-5
    (10.0, 3.2),
    (8.0, 3.5),  # B, room-5
    (8.0, 4.0),
    (4.3, 4.0),  # through door-5-6
    (2.5, 4.0),
    (2.5, 10.0),  # through door-6-1, back at S
)

#: The waypoints the loop may start from (``synthetic-places-loop?start=K``): S (room-1), A (room-3), B (room-5).
PLACES_LOOP_STARTS: tuple[int, ...] = (0, 7, 14)

#: After the first lap, a second loop that leaves room-2 south through door-2-5 into room-5 (a new direction).
PLACES_SECOND_LOOP: tuple[tuple[float, float], ...] = (
    (4.5, 9.0),
    (7.0, 9.0),  # through door-1-2
    (9.3, 9.0),
    (9.3, 5.0),  # through door-2-5: room-5 entered from the north
    (8.0, 4.0),
    (4.3, 4.0),  # through door-5-6
    (2.5, 4.0),
    (2.5, 10.0),  # through door-6-1, back at S
)


def places_plan() -> FloorPlan:
    return build_plan("six-rooms", PLACES_SPACES, PLACES_DOORWAYS, PLACES_FURNITURE)


def places_double_plan() -> FloorPlan:
    return build_plan("six-rooms-double", PLACES_SPACES, (*PLACES_DOORWAYS, PLACES_DOOR_2_5), PLACES_FURNITURE)


def places_loop() -> Route:
    return Route(waypoints=PLACES_LOOP, closed=True)


def places_double_loop() -> Route:
    return Route(waypoints=PLACES_LOOP + PLACES_SECOND_LOOP, closed=True)


# --- A square corridor ring of about 100 m (thesis Experiment 3, Figure 3.20) -------------------------------------
#
# The thesis's error-tolerance route is "approximately 100 meters ... a square-like route" driven start-stop
# (106 views). A corridor ring 2 m wide around a 27 x 17 m block of five rooms, with four rooms outside it,
# thirteen doorways and four alcoves (the corners and door jambs Albot1 tracks), furniture in every room. The
# route follows the corridor's centre line from S in the west corridor, anticlockwise through all four corners
# and back to S: 96 m, every turn the same way, as in Figure 3.20 (so the odometry's turn and heading errors add
# up instead of cancelling, as they do on the office loop's alternating turns).

SQUARE_SPACES: tuple[Space, ...] = (
    Space("corridor", (0.0, 0.0, 31.0, 2.0)),
    Space("corridor", (0.0, 19.0, 31.0, 21.0)),
    Space("corridor", (0.0, 0.0, 2.0, 21.0)),
    Space("corridor", (29.0, 0.0, 31.0, 21.0)),
    Space("corridor", (4.0, 21.0, 5.5, 21.6)),  # alcoves
    Space("corridor", (20.0, -0.6, 21.5, 0.0)),
    Space("corridor", (31.0, 15.0, 31.6, 16.5)),
    Space("corridor", (-0.6, 4.0, 0.0, 5.5)),
    Space("room-a", (2.2, 2.2, 10.9, 9.4)),  # inside the ring
    Space("room-b", (11.1, 2.2, 19.9, 9.4)),
    Space("room-c", (20.1, 2.2, 28.8, 9.4)),
    Space("room-d", (2.2, 9.6, 14.9, 18.8)),
    Space("room-e", (15.1, 9.6, 28.8, 18.8)),
    Space("room-f", (6.0, -5.2, 13.0, -0.2)),  # outside it
    Space("room-g", (31.2, 6.0, 36.0, 12.0)),
    Space("room-h", (18.0, 21.2, 25.0, 26.0)),
    Space("room-i", (-5.0, 12.0, -0.2, 17.0)),
)

SQUARE_DOORWAYS: tuple[DoorwaySpec, ...] = (
    DoorwaySpec("room-a-south", (6.5, 2.1), "x", 0.9),
    DoorwaySpec("room-b-south", (15.5, 2.1), "x", 0.9),
    DoorwaySpec("room-c-south", (24.5, 2.1), "x", 0.9),
    DoorwaySpec("room-c-east", (28.9, 6.0), "y", 0.9),
    DoorwaySpec("room-e-east", (28.9, 14.0), "y", 1.0),
    DoorwaySpec("room-e-north", (22.0, 18.9), "x", 0.9),
    DoorwaySpec("room-d-north", (8.0, 18.9), "x", 1.0),
    DoorwaySpec("room-d-west", (2.1, 14.0), "y", 0.9),
    DoorwaySpec("room-a-west", (2.1, 5.5), "y", 0.9),
    DoorwaySpec("room-f", (9.5, -0.1), "x", 1.0),
    DoorwaySpec("room-g", (31.1, 9.0), "y", 1.0),
    DoorwaySpec("room-h", (21.5, 21.1), "x", 1.0),
    DoorwaySpec("room-i", (-0.1, 14.5), "y", 1.0),
)

SQUARE_FURNITURE: tuple[Rect, ...] = (
    (4.0, 7.0, 6.0, 8.0),
    (13.0, 6.5, 15.0, 7.5),
    (24.0, 5.0, 26.0, 6.0),
    (6.0, 14.0, 9.0, 15.0),
    (20.0, 12.0, 23.0, 13.0),
    (8.0, -4.0, 11.0, -3.0),
    (33.0, 8.0, 35.0, 10.0),
    (20.0, 23.5, 23.0, 24.5),
    (-4.0, 13.5, -2.0, 15.5),
)


def square_plan() -> FloorPlan:
    return build_plan("square", SQUARE_SPACES, SQUARE_DOORWAYS, SQUARE_FURNITURE)


def square_loop() -> Route:
    """S (1, 10.5) south, then east, north, west along the ring and south back to S: 96 m."""
    return Route(
        waypoints=((1.0, 10.5), (1.0, 1.0), (30.0, 1.0), (30.0, 20.0), (1.0, 20.0), (1.0, 10.5)),
        closed=True,
    )
