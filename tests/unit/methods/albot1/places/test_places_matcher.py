"""The structural matcher (Algorithm 6): a room against a moved copy of itself, against another room."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry.segments import transform_segments
from albot1.methods.albot1.places.accel import places_kernels
from albot1.methods.albot1.places.config import Albot1PlacesConfig
from albot1.methods.albot1.places.matcher import (
    confirm,
    merge_collinear,
    robot_sides,
    structural,
    trigger_threshold,
)

KERNELS = [places_kernels(False), places_kernels(True)]
PARAMS = Albot1PlacesConfig().match_params()


def box(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    """A rectangle's four sides, counter-clockwise (seen from inside, as a view of a room orders them)."""
    return [[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]]


def furniture(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    """A piece of furniture seen from outside: its sides run clockwise."""
    return [[x1, y0, x0, y0], [x0, y0, x0, y1], [x0, y1, x1, y1], [x1, y1, x1, y0]]


# A 7 x 6 m room with a desk, a cabinet and a pillar (own frame); the robot stands at (3, 2.5) facing +y.
ROOM = np.array(box(0, 0, 7, 6) + furniture(1, 4.5, 3, 5.2) + furniture(5, 1, 6.2, 1.6) + furniture(3.6, 2.8, 4.1, 3.3))
# Another room: 6 x 5 m, furniture elsewhere and askew.
OTHER = np.array(box(0, 0, 6, 5) + furniture(0.5, 0.5, 1.5, 2.5) + furniture(4.2, 3.5, 5.6, 4.1))
OTHER = np.vstack(
    [OTHER, transform_segments((3.0, 2.0, math.radians(30.0)), np.array(furniture(-0.5, -0.2, 0.5, 0.2)))]
)
ROBOT = (3.0, 2.5, 0.0)
POSE = (1.7, -2.2, math.radians(25.0))


def current_view(
    surfaces: np.ndarray, pose: tuple[float, float, float]
) -> tuple[np.ndarray, tuple[float, float, float]]:
    """``surfaces`` (own frame) as seen in a map where the room lies at ``pose``, and the robot there too."""
    placed = transform_segments(pose, surfaces)
    robot = transform_segments(pose, np.array([[ROBOT[0], ROBOT[1], ROBOT[0], ROBOT[1] + 1.0]]))[0]
    return placed, (float(robot[0]), float(robot[1]), pose[2])


def seen_empty(pose: tuple[float, float, float], half: float = 1.0) -> list[np.ndarray]:
    """A small polygon around the robot: the space its views saw empty."""
    square = np.array([[-half, -half], [half, -half], [half, half], [-half, half]]) + np.array(ROBOT[:2])
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return [
        np.column_stack([pose[0] + c * square[:, 0] - s * square[:, 1], pose[1] + s * square[:, 0] + c * square[:, 1]])
    ]


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_room_is_recognised_in_a_rotated_and_translated_copy_of_itself(kernels) -> None:
    current, robot = current_view(ROOM, POSE)
    match = confirm(
        structural(current, PARAMS), structural(ROOM, PARAMS), robot, seen_empty(POSE), POSE, PARAMS, kernels
    )
    assert match.confirmed and match.matches >= 5
    np.testing.assert_allclose(match.place_in_map[:2], POSE[:2], atol=1e-6)
    assert match.place_in_map[2] == pytest.approx(POSE[2], abs=1e-9)


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_different_room_is_not_recognised(kernels) -> None:
    current, robot = current_view(OTHER, POSE)
    match = confirm(
        structural(current, PARAMS), structural(ROOM, PARAMS), robot, seen_empty(POSE), POSE, PARAMS, kernels
    )
    assert not match.confirmed


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_matches_on_one_side_of_the_robot_only_do_not_confirm(kernels) -> None:
    # only what lies left of the robot (x < 3 in the room's frame) was seen
    left = ROOM[(ROOM[:, 0] + ROOM[:, 2]) / 2 < ROBOT[0]]
    current, robot = current_view(left, POSE)
    assert (robot_sides(current, robot) < 0).all()
    match = confirm(current, structural(ROOM, PARAMS), robot, seen_empty(POSE), POSE, PARAMS, kernels)
    assert not match.confirmed


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_remembered_surface_where_the_view_saw_empty_space_refuses_the_hypothesis(kernels) -> None:
    # the remembered room has a cabinet in the middle of the floor the robot now sees empty
    remembered = np.vstack([ROOM, furniture(2.5, 2.0, 3.5, 2.2)])
    current, robot = current_view(ROOM, POSE)
    args = (structural(current, PARAMS), structural(remembered, PARAMS), robot, seen_empty(POSE, 1.5), POSE)
    assert not confirm(*args, PARAMS, kernels).confirmed
    lenient = Albot1PlacesConfig(match_max_conflicts=4).match_params()
    assert confirm(*args, lenient, kernels).confirmed


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_hypothesis_far_from_where_the_map_put_the_place_is_refused(kernels) -> None:
    current, robot = current_view(ROOM, POSE)
    far = (POSE[0] + 6.0, POSE[1], POSE[2])
    match = confirm(
        structural(current, PARAMS), structural(ROOM, PARAMS), robot, seen_empty(POSE), far, PARAMS, kernels
    )
    assert not match.confirmed


def test_collinear_pieces_merge_into_one_structure() -> None:
    pieces = np.array([[0.0, 0.0, 1.0, 0.0], [1.2, 0.02, 2.5, 0.0], [2.8, -0.05, 4.0, 0.0], [0.0, 1.0, 4.0, 1.0]])
    merged = merge_collinear(pieces, math.radians(5.0), 0.2, 0.4)
    assert len(merged) == 2
    assert min(merged[:, 0].min(), merged[:, 2].min()) == pytest.approx(0.0, abs=0.06)
    assert max(merged[:, 0].max(), merged[:, 2].max()) == pytest.approx(4.0, abs=0.06)
    # opposite directions (the two faces of a wall) and a 1 m gap (a doorway) stay apart
    apart = np.array([[0.0, 0.0, 1.0, 0.0], [2.0, 0.0, 1.5, 0.0], [2.5, 0.0, 4.0, 0.0]])
    assert len(merge_collinear(apart, math.radians(5.0), 0.2, 0.4)) == 3


def test_trigger_threshold_grows_with_the_place() -> None:
    assert trigger_threshold(5, PARAMS) == 4
    assert trigger_threshold(40, PARAMS) == 8
    assert trigger_threshold(41, PARAMS) == 9
