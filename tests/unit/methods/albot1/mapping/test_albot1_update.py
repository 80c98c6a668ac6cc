"""The map update (thesis 3.1.7, Algorithm 3, Figures 3.12-3.13) and the perceptual map's bookkeeping."""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
import pytest

from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.perceptual_map import PerceptualMap
from albot1.methods.albot1.mapping.update import UpdateParams, update_map, view_polygon

MarginFrom = Literal["surfaces", "boundary"]

# A view (thesis frame, robot at the origin facing +y): a wall 3 m ahead with a gap.
VIEW = np.array([[-2.0, 3.0, 0.0, 3.0], [0.5, 3.0, 2.0, 3.0]])
MAP = {
    "inside": [-0.5, 2.0, 0.5, 2.0],
    "near_boundary": [-0.5, 3.3, 0.5, 3.3],  # 30 cm outside the polygon: within 40 cm
    "far": [-0.5, 5.0, 0.5, 5.0],
    "crossing": [-3.0, 1.0, 3.0, 1.0],  # crosses the view, both ends outside: kept
    "extend": [-4.0, 3.0, -1.0, 3.0],  # Figure 3.13's S_e, continues the first view surface
    "reduce": [0.1, 2.9, 5.0, 2.9],  # Figure 3.13's S_r, reaches into the view past the second
    "clip": [0.8, 1.5, 4.0, 1.5],  # partly inside, nothing corresponding in the view
}


def build_map() -> tuple[PerceptualMap, dict[str, int]]:
    pmap = PerceptualMap()
    ids = pmap.add(np.array(list(MAP.values())), scan=0)
    return pmap, dict(zip(MAP, ids.tolist()))


def test_view_polygon_is_the_robot_then_the_endpoints_left_to_right() -> None:
    poly = view_polygon(VIEW, (0.0, 0.0), "robot_and_endpoints")
    np.testing.assert_array_equal(poly, [[0, 0], [-2, 3], [0, 3], [0.5, 3], [2, 3]])
    assert view_polygon(VIEW, (0.0, 0.0), "endpoints").shape == (4, 2)


@pytest.mark.parametrize("margin_from", ["surfaces", "boundary"])
def test_update_deletes_exactly_the_covered_surfaces_and_extends_or_trims_as_in_figure_3_13(
    margin_from: MarginFrom,
) -> None:
    pmap, ids = build_map()
    out = update_map(pmap, VIEW, (0.0, 0.0), scan=7, params=UpdateParams(margin_from=margin_from))
    assert sorted(out.deleted.tolist()) == sorted([ids["inside"], ids["near_boundary"]])
    assert out.extended.tolist() == [ids["extend"]]
    assert sorted(out.trimmed.tolist()) == sorted([ids["reduce"], ids["clip"]])
    # Both view surfaces were absorbed by the surfaces they correspond to: nothing new is added.
    assert out.added.tolist() == []
    assert out.view_ids.tolist() == [ids["extend"], ids["reduce"]]
    segs = dict(zip(pmap.ids().tolist(), pmap.segments()))
    assert set(segs) == {ids["far"], ids["crossing"], ids["extend"], ids["reduce"], ids["clip"]}
    # S_e runs from its outside end to the far end of the view surface; S_r is cut back to it.
    np.testing.assert_allclose(segs[ids["extend"]], [-4.0, 3.0, 0.0, 3.0])
    np.testing.assert_allclose(segs[ids["reduce"]], [0.5, 3.0, 5.0, 2.9])
    # The clipped surface starts where it enters the covered region: the polygon's side
    # robot->(2, 3) crosses y = 1.5 at x = 1; grown by 40 cm it is 0.4 * sqrt(13) / 3 farther.
    enter = 1.0 if margin_from == "surfaces" else 1.0 + 0.4 * math.sqrt(13.0) / 3.0
    np.testing.assert_allclose(segs[ids["clip"]], [enter, 1.5, 4.0, 1.5], atol=1e-3)
    np.testing.assert_array_equal(segs[ids["far"]], MAP["far"])
    np.testing.assert_array_equal(segs[ids["crossing"]], MAP["crossing"])
    assert pmap.history(ids["extend"]) == [("added", 0), ("extended", 7)]
    assert pmap.history(ids["inside"]) == [("added", 0), ("deleted", 7)]


@pytest.mark.parametrize("margin_from", ["surfaces", "boundary"])
def test_a_wall_running_on_behind_the_field_of_view_edge(margin_from: MarginFrom) -> None:
    # The map's wall starts 20 cm behind the robot (the previous update); the view sees it
    # from beside the robot (x = -1 in the thesis frame) forwards.
    pmap = PerceptualMap()
    sid = int(pmap.add(np.array([[-1.0, -0.2, -1.0, 4.0]]), scan=0)[0])
    view = np.array([[-1.0, 0.0, -1.0, 4.5], [-1.0, 4.5, 1.0, 4.5]])
    out = update_map(pmap, view, (0.0, 0.0), scan=2, params=UpdateParams(margin_from=margin_from))
    if margin_from == "surfaces":
        # Partly outside: extended onto the view's wall, keeping its part behind the robot.
        assert out.extended.tolist() == [sid]
        np.testing.assert_allclose(pmap.segments(np.array([sid]))[0], [-1.0, -0.2, -1.0, 4.5])
    else:
        # 20 cm from the polygon's side: deleted, and the wall behind the robot is lost.
        assert out.deleted.tolist() == [sid]
        assert pmap.segments().min(axis=0)[1] == 0.0


@pytest.mark.parametrize("margin_from", ["surfaces", "boundary"])
def test_an_end_outside_the_polygon_but_within_the_margin_counts_as_inside_for_lines_11_12(
    margin_from: MarginFrom,
) -> None:
    # Algorithm 3 line 11, "one edge point of S_i is inside the polygon and the other is outside", read with line 9's
    # region (inside or within 40 cm; docs/albot1-mapper.md item 21). This wall runs 20 cm behind the view's first
    # surface (y = 3.2 against 3): its right end is outside the polygon but within the margin, its left end far out.
    # Literally neither line 9 nor line 11 would touch it; read so, it corresponds to the view surface 20 cm away and
    # is extended onto it: from its outside end to that surface's far end.
    pmap = PerceptualMap()
    sid = int(pmap.add(np.array([[-5.0, 3.2, -1.5, 3.2]]), scan=0)[0])
    out = update_map(pmap, VIEW, (0.0, 0.0), scan=4, params=UpdateParams(margin_from=margin_from))
    assert out.extended.tolist() == [sid] and out.deleted.tolist() == [] and out.view_ids.tolist()[0] == sid
    np.testing.assert_array_equal(pmap.segments(np.array([sid]))[0], [-5.0, 3.2, 0.0, 3.0])


def test_update_keeps_partial_surfaces_whole_when_asked_and_adds_unmatched_view_surfaces() -> None:
    pmap, ids = build_map()
    params = UpdateParams(partial_without_match="keep", correspond_distance=0.01, correspond_angle=1e-6)
    out = update_map(pmap, VIEW, (0.0, 0.0), scan=3, params=params)
    # "extend" touches its (exactly parallel) view surface, so it still corresponds.
    assert out.extended.tolist() == [ids["extend"]] and out.trimmed.tolist() == []
    # "reduce" (10 cm off) and "clip" have no partner now and are kept whole.
    for name in ("reduce", "clip"):
        np.testing.assert_allclose(pmap.segments(np.array([ids[name]]))[0], MAP[name])
        assert pmap.history(ids[name]) == [("added", 0)]
    # The second view surface is added as a new surface.
    assert out.added.tolist() == [len(MAP)]
    assert out.view_ids.tolist() == [ids["extend"], len(MAP)]


def test_update_with_an_empty_view_changes_nothing() -> None:
    pmap, ids = build_map()
    out = update_map(pmap, np.empty((0, 4)), (0.0, 0.0), scan=1, params=UpdateParams())
    assert len(pmap) == len(MAP) and out.deleted.size == 0 and out.added.size == 0


def test_perceptual_map_ids_history_and_box_query() -> None:
    pmap = PerceptualMap()
    a = pmap.add(np.array([[0.0, 0.0, 10.0, 10.0], [50.0, 50.0, 51.0, 50.0]]), scan=2)
    assert a.tolist() == [0, 1]
    b = pmap.add(np.array([[5.0, 0.0, 5.0, 1.0]]), scan=3)
    assert b.tolist() == [2]
    # The diagonal surface is found from a box it passes through, the far one is not.
    assert pmap.query(4.6, 4.6, 5.4, 5.4).tolist() == [0]
    assert 1 in pmap.query(49.0, 49.0, 52.0, 51.0).tolist()
    pmap.replace(0, np.array([0.0, 0.0, 1.0, 1.0]), scan=4, event="trimmed")
    assert 0 not in pmap.query(8.0, 8.0, 9.0, 9.0).tolist()
    pmap.delete(1, scan=5)
    assert len(pmap) == 2 and pmap.ids().tolist() == [0, 2]
    assert pmap.history(1) == [("added", 2), ("deleted", 5)]
    with pytest.raises(KeyError, match="surface id 1"):
        pmap.delete(1, scan=6)
    props = pmap.properties()
    assert props[0] == {
        "id": 0,
        "added_at": 2,
        "history": [{"event": "added", "scan": 2}, {"event": "trimmed", "scan": 4}],
    }


def test_perceptual_map_grows_past_its_initial_capacity() -> None:
    pmap = PerceptualMap()
    segs = np.column_stack([np.arange(600.0), np.zeros(600), np.arange(600.0) + 0.5, np.zeros(600)])
    ids = pmap.add(segs, scan=0)
    assert ids[-1] == 599 and len(pmap) == 600
    np.testing.assert_array_equal(pmap.segments(), segs)


def _random_view(rng: np.random.Generator, robot: np.ndarray) -> np.ndarray:
    """Surfaces around ``robot``, left to right like a view: a chain of endpoints at decreasing bearings."""
    bearings = np.sort(rng.uniform(-1.4, 1.4, 2 * int(rng.integers(1, 8))))[::-1] + math.pi / 2
    ranges = rng.uniform(0.5, 4.0, bearings.size)
    pts = robot + np.column_stack([ranges * np.cos(bearings), ranges * np.sin(bearings)])
    return np.ascontiguousarray(pts.reshape(-1, 4))


@pytest.mark.parametrize("clip", ["clip", "keep"])
@pytest.mark.parametrize("margin_from", ["surfaces", "boundary"])
@pytest.mark.parametrize("polygon", ["robot_and_endpoints", "endpoints"])
def test_update_compiled_and_as_written_edit_the_map_identically(clip: str, margin_from: str, polygon: str) -> None:
    """The update kernel edits the map's arrays in place: 40 updates on two copies, compared bit for bit."""
    params = UpdateParams(partial_without_match=clip, margin_from=margin_from, polygon=polygon)  # type: ignore[arg-type]
    rng = np.random.default_rng(3)
    maps = (PerceptualMap(), PerceptualMap())
    for pmap in maps:
        pmap.add(np.random.default_rng(4).uniform(-4.0, 4.0, (60, 4)), scan=0)
    kernel_sets = (MappingKernels(True), MappingKernels(False))
    edits = 0
    for scan in range(1, 41):
        robot = rng.uniform(-3.0, 3.0, 2)
        view = _random_view(rng, robot)
        fast, slow = (update_map(p, view, (robot[0], robot[1]), scan, params, k) for p, k in zip(maps, kernel_sets))
        for name in ("view_ids", "deleted", "extended", "trimmed", "added"):
            np.testing.assert_array_equal(getattr(fast, name), getattr(slow, name))
        edits += len(fast.deleted) + len(fast.extended) + len(fast.trimmed)
    a, b = maps
    assert (a.n, a.live, a.n_events) == (b.n, b.live, b.n_events)
    np.testing.assert_array_equal(a.seg[: a.n].view(np.int64), b.seg[: b.n].view(np.int64))
    np.testing.assert_array_equal(a.live_id[: a.live], b.live_id[: b.live])
    np.testing.assert_array_equal(a.events[: a.n_events], b.events[: b.n_events])
    assert a.properties() == b.properties()
    assert edits > 40  # the updates did delete, extend or trim


def test_update_matches_the_per_surface_operations() -> None:
    """The compiled update leaves the map as deleting, replacing and adding surface by surface would."""
    pmap, _ = build_map()
    ref, _ = build_map()
    out = update_map(pmap, VIEW, (0.0, 0.0), scan=7, params=UpdateParams())
    for sid in out.deleted.tolist():
        ref.delete(sid, 7)
    for event, ids in (("extended", out.extended), ("trimmed", out.trimmed)):
        for sid in ids.tolist():
            ref.replace(sid, pmap.segments(np.array([sid]))[0], 7, event)
    assert ref.add(VIEW[out.view_ids >= len(MAP)], 7).tolist() == out.added.tolist()
    assert ref.ids().tolist() == pmap.ids().tolist() and ref.properties() == pmap.properties()
    for box in ((-5.0, -5.0, 5.0, 5.0), (-0.6, 1.9, 0.6, 2.1), (0.0, 3.0, 0.0, 3.0)):
        assert ref.query(*box).tolist() == pmap.query(*box).tolist()
