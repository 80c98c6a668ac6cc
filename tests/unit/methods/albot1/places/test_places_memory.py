"""The place memory (Algorithms 5 and 7): places from visits, exits and their links, merging, the export."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from albot1.geometry.se2 import between_pose
from albot1.geometry.segments import transform_segments
from albot1.methods.albot1.places.config import Albot1PlacesConfig
from albot1.methods.albot1.places.kernels import PlacesKernels
from albot1.methods.albot1.places.memory import PlaceNetwork, invert, same_surfaces
from albot1.methods.albot1.places.navigation import align_at_exit, nearest_prediction, predict
from albot1.methods.albot1.places.network import extent, network_files


def network() -> PlaceNetwork:
    return PlaceNetwork(
        same_angle=math.radians(5.0), same_gap=0.4, link_distance=1.0, same_any=PlacesKernels(False).same_any
    )


ROOM_A = np.array([[0.0, 0.0, 4.0, 0.0], [4.0, 0.0, 4.0, 3.0], [4.0, 3.0, 0.0, 3.0]])
DOOR_AB = np.array([4.0, 1.0, 4.0, 2.0])  # A on its left (x < 4)
ROOM_B = np.array([[4.2, 0.0, 8.0, 0.0], [8.0, 0.0, 8.0, 3.0]])
DOOR_BC = np.array([8.0, 1.0, 8.0, 2.0])


def reverse(seg: np.ndarray) -> np.ndarray:
    return np.concatenate([seg[2:], seg[:2]])


def test_crossing_exits_creates_places_with_linked_exits() -> None:
    net = network()
    a = net.start_visit(0, (0.0, 0.0, 0.0))
    place_a, exit_ab = net.close(a, ROOM_A, DOOR_AB, 10)
    b = net.start_visit(10, (4.5, 1.5, 0.0), reverse(DOOR_AB), (place_a, exit_ab))
    place_b, exit_bc = net.close(b, ROOM_B, DOOR_BC, 20)
    assert (place_a, place_b) == (0, 1) and len(net.places) == 2
    # a place's surfaces are kept in its own frame (B's frame is its entry pose)
    np.testing.assert_allclose(net.places[1].surfaces, transform_segments(invert((4.5, 1.5, 0.0)), ROOM_B))
    # A's exit leads to B's entry exit and back (Algorithm 5 line 12)
    entry_b = net.visits[1].entry_exit
    assert net.leads(place_a, exit_ab) == (place_b, entry_b)
    assert net.leads(place_b, entry_b) == (place_a, exit_ab)
    assert net.leads(place_b, exit_bc) is None
    # each exit record has its place on the left
    for place in net.places:
        for record in place.exits:
            a_, b_ = record.segment[:2], record.segment[2:]
            centre = place.surfaces.reshape(-1, 2).mean(axis=0)
            assert (b_[0] - a_[0]) * (centre[1] - a_[1]) - (b_[1] - a_[1]) * (centre[0] - a_[0]) > 0


def test_a_recognised_visit_is_combined_into_its_place_without_duplicates() -> None:
    net = network()
    a = net.start_visit(0, (0.0, 0.0, 0.0))
    net.close(a, ROOM_A, DOOR_AB, 10)
    again = net.start_visit(30, (1.0, 1.0, 0.5))
    # the map drifted: place A now lies 0.3 m along x; the visit sees A's walls there, plus one new surface
    moved = (0.3, 0.0, 0.0)
    seen = np.vstack([transform_segments(moved, ROOM_A), [[0.3, 2.0, 1.3, 2.0]]])
    net.assign(again, 0, moved, 31)
    place, _ = net.close(again, seen, transform_segments(moved, DOOR_AB[None])[0], 40)
    assert place == 0 and len(net.places) == 1
    assert len(net.places[0].surfaces) == 4
    np.testing.assert_allclose(net.places[0].surfaces[-1], [0.0, 2.0, 1.0, 2.0], atol=1e-12)
    assert len(net.places[0].exits) == 1  # the same door, recognised in the place's frame


def test_confirming_a_second_place_merges_the_younger_into_the_older() -> None:
    net = network()
    first = net.start_visit(0, (0.0, 0.0, 0.0))
    net.close(first, ROOM_A, DOOR_AB, 10)
    other = net.start_visit(10, (0.0, 0.0, 0.0))
    net.close(other, ROOM_B, DOOR_BC, 20)
    visit = net.start_visit(30, (0.0, 0.0, 0.0))
    net.assign(visit, 1, (0.0, 0.0, 0.0), 31)
    # now the same visit is matched to place 0, whose frame lies 0.2 m off: one place
    kept = net.assign(visit, 0, (0.2, 0.0, 0.0), 32)
    assert kept == 0 and net.places[1].merged_into == 0 and net.find(1) == 0
    assert len(net.live_places()) == 1
    assert visit.place == 0 and visit.place_in_map == (0.2, 0.0, 0.0)
    assert {1} <= set(net.places[0].visits)


@pytest.mark.parametrize("accelerate", [False, True], ids=["plain", "jit"])
def test_same_surfaces_needs_direction_and_nearness(accelerate: bool) -> None:
    a = np.array([[0.0, 0.0, 2.0, 0.0]])
    b = np.array([[0.5, 0.3, 1.5, 0.31], [1.5, 0.3, 0.5, 0.3], [0.5, 0.6, 1.5, 0.6], [0.5, 0.3, 1.5, 0.5]])
    assert same_surfaces(a, b, math.radians(5.0), 0.4).tolist() == [[True, False, False, False]]
    a_has, b_has = PlacesKernels(accelerate).same_any(a, b, math.radians(5.0), 0.4)
    assert a_has.tolist() == [True] and b_has.tolist() == [True, False, False, False]
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, 5, (40, 4)), rng.uniform(0, 5, (30, 4))
    same = same_surfaces(x, y, math.radians(20.0), 0.4)
    x_has, y_has = PlacesKernels(accelerate).same_any(x, y, math.radians(20.0), 0.4)
    assert x_has.tolist() == same.any(axis=1).tolist() and y_has.tolist() == same.any(axis=0).tolist()


def test_exits_are_predicted_aligned_at_the_exit_crossed() -> None:
    net = network()
    b = net.start_visit(10, (4.5, 1.5, 0.0), reverse(DOOR_AB), None)
    place_b, exit_bc = net.close(b, ROOM_B, DOOR_BC, 20)
    entry = net.exit(place_b, b.entry_exit)
    assert entry is not None
    # later the robot enters B through the same door, which the drifted map now has 0.5 m off and turned 10 deg
    drift = (0.5, -0.2, math.radians(10.0))
    crossed = transform_segments(drift, reverse(DOOR_AB)[None])[0]
    place_in_map = align_at_exit(entry.segment, crossed)
    expected = (
        drift[0] + math.cos(drift[2]) * 4.5 - math.sin(drift[2]) * 1.5,
        drift[1] + math.sin(drift[2]) * 4.5 + math.cos(drift[2]) * 1.5,
        drift[2],
    )
    np.testing.assert_allclose(place_in_map, expected, atol=1e-9)
    predictions = predict(net.places[place_b].exits, place_b, place_in_map, 50, skip=b.entry_exit)
    assert [p.exit for p in predictions] == [exit_bc]
    true_bc = transform_segments(drift, DOOR_BC[None])[0]
    found = nearest_prediction(predictions, true_bc, 2.0)
    assert found is not None
    _, aligned, not_aligned = found
    assert aligned == pytest.approx(0.0, abs=1e-9)
    assert not_aligned == pytest.approx(float(np.hypot(*(0.5 * (true_bc[:2] + true_bc[2:]) - [8.0, 1.5]))))
    assert nearest_prediction(predictions, true_bc + 5.0, 2.0) is None


def test_places_json_and_graphml_describe_the_network() -> None:
    net = network()
    a = net.start_visit(0, (0.0, 0.0, 0.0))
    place_a, exit_ab = net.close(a, ROOM_A, DOOR_AB, 10)
    b = net.start_visit(10, (4.5, 1.5, 0.0), reverse(DOOR_AB), (place_a, exit_ab))
    net.close(b, ROOM_B, DOOR_BC, 20)
    files = network_files(net, crossings=[], revisits=[], predictions=[], scans=30, config=Albot1PlacesConfig())
    record = files["places.json"]
    assert [p["id"] for p in record["places"]] == [0, 1]
    assert record["links"] == [{"place": 0, "exit": exit_ab, "to_place": 1, "to_exit": net.visits[1].entry_exit}]
    assert [v["last_scan"] for v in record["visits"]] == [10, 20]
    # REP-103 export: a thesis-frame segment (x1, y1, x2, y2) -> (y1, -x1, y2, -x2)
    assert record["places"][0]["surfaces"][0] == [0.0, -0.0, 0.0, -4.0]
    assert record["config"]["exit_max_width_m"] == 1.2 and "motion_model" not in record["config"]
    root = ET.fromstring(files["places.graphml"])
    ns = {"g": "http://graphml.graphdrawing.org/xmlns"}
    assert len(root.findall(".//g:node", ns)) == 2 and len(root.findall(".//g:edge", ns)) == 1
    radius, centre = extent(net.places[0])
    # the box of the surfaces' midpoints (2, 0), (4, 1.5), (2, 3)
    assert radius == pytest.approx(0.5 * math.hypot(2.0, 3.0)) and centre == pytest.approx((3.0, 1.5))


def test_between_and_invert_agree() -> None:
    pose = (1.0, -2.0, 0.3)
    np.testing.assert_allclose(between_pose(pose, (0.0, 0.0, 0.0)), invert(pose))
