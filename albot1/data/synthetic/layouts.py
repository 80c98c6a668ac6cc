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

from albot1.data.synthetic.floorplan import DoorwaySpec, FloorPlan, Rect, Space, build_plan
from albot1.data.synthetic.route import Route

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
