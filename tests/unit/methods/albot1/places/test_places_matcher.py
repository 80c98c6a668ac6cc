"""The structural matcher (Algorithm 6): a room against a moved copy of itself, against another room."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry.segments import transform_segments
from albot1.methods.albot1.places.config import Albot1PlacesConfig
from albot1.methods.albot1.places.kernels import PlacesKernels
from albot1.methods.albot1.places.matcher import (
    confirm,
    robot_sides,
    structural,
    trigger_threshold,
)

KERNELS = [PlacesKernels(False), PlacesKernels(True)]
PARAMS = Albot1PlacesConfig().match_params()


def box(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    """A rectangle's four sides, counter-clockwise (seen from inside, as a view of a room orders them)."""
    return [[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]]


def furniture(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    """A piece of furniture seen from outside: its sides run clockwise."""
    return [[x1, y0, x0, y0], [x0, y0, x0, y1], [x0, y1, x1, y1], [x1, y1, x1, y0]]


# A 7 x 6 m room with a desk, a cabinet and a pillar (own frame); the robot stands at (3, 2.5) facing +y.
ROOM = np.array(box(0, 0, 7, 6) + furniture(1, 4.5, 3, 5.2) + furniture(5, 1, 6.2, 1.6) + furniture(3.6, 2.8, 4.1, 3.3))
# Another room: 6 x 8 m, a long bench along one wall and two pieces standing askew.
OTHER = np.vstack(
    [
        np.array(box(0, 0, 6, 8) + furniture(4.9, 1.0, 5.6, 5.0)),
        transform_segments((2.0, 5.5, math.radians(30.0)), np.array(furniture(-0.6, -0.3, 0.6, 0.3))),
        transform_segments((2.5, 2.0, math.radians(-40.0)), np.array(furniture(-0.5, -0.25, 0.5, 0.25))),
    ]
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


def seen_empty(pose: tuple[float, float, float], width: float, depth: float) -> list[np.ndarray]:
    """The room's floor (its walls' rectangle) placed at ``pose``: the space the views of the room saw."""
    corners = np.array([[0.0, 0.0], [width, 0.0], [width, depth], [0.0, depth]])
    c, s = math.cos(pose[2]), math.sin(pose[2])
    x = pose[0] + c * corners[:, 0] - s * corners[:, 1]
    y = pose[1] + s * corners[:, 0] + c * corners[:, 1]
    return [np.column_stack([x, y])]


def match_room(current_room: np.ndarray, remembered: np.ndarray, size: tuple[float, float], prior, params, kernels):
    current, robot = current_view(current_room, POSE)
    return confirm(
        structural(current, params, kernels),
        structural(remembered, params, kernels),
        robot,
        seen_empty(POSE, *size),
        prior,
        params,
        kernels,
    )


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_room_is_recognised_in_a_rotated_and_translated_copy_of_itself(kernels) -> None:
    match = match_room(ROOM, ROOM, (7, 6), POSE, PARAMS, kernels)
    assert match.confirmed and match.matches >= 5
    np.testing.assert_allclose(match.place_in_map[:2], POSE[:2], atol=1e-6)
    assert match.place_in_map[2] == pytest.approx(POSE[2], abs=1e-9)


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_different_room_is_not_recognised(kernels) -> None:
    assert not match_room(OTHER, ROOM, (6, 8), POSE, PARAMS, kernels).confirmed
    # with the thesis's criterion alone (no empty-space test) two furnished rectangles do match
    thesis_only = Albot1PlacesConfig(match_max_conflicts=99).match_params()
    assert match_room(OTHER, ROOM, (6, 8), POSE, thesis_only, kernels).confirmed


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_matches_on_one_side_of_the_robot_only_do_not_confirm(kernels) -> None:
    # only what lies left of the robot (x < 3 in the room's frame) was seen
    left = ROOM[(ROOM[:, 0] + ROOM[:, 2]) / 2 < ROBOT[0]]
    current, robot = current_view(left, POSE)
    assert (robot_sides(current, robot) < 0).all()
    assert not match_room(left, ROOM, (7, 6), POSE, PARAMS, kernels).confirmed


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_remembered_surface_where_the_view_saw_empty_space_refuses_the_hypothesis(kernels) -> None:
    # the remembered room has a cabinet in the middle of the floor the robot now sees empty
    remembered = np.vstack([ROOM, furniture(2.5, 3.8, 3.5, 4.0)])
    assert not match_room(ROOM, remembered, (7, 6), POSE, PARAMS, kernels).confirmed
    lenient = Albot1PlacesConfig(match_max_conflicts=2).match_params()  # its two long sides
    match = match_room(ROOM, remembered, (7, 6), POSE, lenient, kernels)
    assert match.confirmed
    np.testing.assert_allclose(match.place_in_map[:2], POSE[:2], atol=1e-6)


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_hypothesis_far_from_where_the_map_put_the_place_is_refused(kernels) -> None:
    far = (POSE[0] + 6.0, POSE[1], POSE[2])
    assert not match_room(ROOM, ROOM, (7, 6), far, PARAMS, kernels).confirmed
    turned = (POSE[0], POSE[1], POSE[2] + math.radians(60.0))
    assert not match_room(ROOM, ROOM, (7, 6), turned, PARAMS, kernels).confirmed


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_collinear_pieces_merge_into_one_structure(kernels) -> None:
    pieces = np.array([[0.0, 0.0, 1.0, 0.0], [1.2, 0.02, 2.5, 0.0], [2.8, -0.05, 4.0, 0.0], [0.0, 1.0, 4.0, 1.0]])
    merged = kernels.merge_collinear(pieces, math.radians(5.0), 0.2, 0.4)
    assert len(merged) == 2
    assert min(merged[:, 0].min(), merged[:, 2].min()) == pytest.approx(0.0, abs=0.06)
    assert max(merged[:, 0].max(), merged[:, 2].max()) == pytest.approx(4.0, abs=0.06)
    # opposite directions (the two faces of a wall) and a 1 m gap (a doorway) stay apart
    apart = np.array([[0.0, 0.0, 1.0, 0.0], [2.0, 0.0, 1.5, 0.0], [2.5, 0.0, 4.0, 0.0]])
    assert len(kernels.merge_collinear(apart, math.radians(5.0), 0.2, 0.4)) == 3


def test_trigger_threshold_grows_with_the_place() -> None:
    assert trigger_threshold(5, PARAMS) == 4
    assert trigger_threshold(40, PARAMS) == 8
    assert trigger_threshold(41, PARAMS) == 9
