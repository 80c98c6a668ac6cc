"""The embedded worlds: names, sizes, ground truth, determinism, crossings and metadata."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

from albot1.data.errors import DatasetNotFoundError
from albot1.data.synthetic import layouts, worlds
from albot1.data.synthetic.errors import SyntheticWorldError, UnknownWorldError
from albot1.data.synthetic.route import Route, repeat_laps, sample
from albot1.geometry import se2

NAMES = [
    "synthetic-office-loop",
    "synthetic-office-startstop",
    "synthetic-corridor",
    "synthetic-office-long",
    "synthetic-office-startstop-10deg",
    "synthetic-places-loop",  # tests/unit/data/synthetic/test_synthetic_places_worlds.py
    "synthetic-places-double-loop",
    "synthetic-square-startstop",  # tests/unit/data/synthetic/test_synthetic_square_world.py
]
QUICK = [*NAMES[:3], NAMES[4]]


def point_to_walls(points: np.ndarray, walls: np.ndarray) -> np.ndarray:
    """Distance from each point (K, 2) to the nearest wall segment."""
    a, b = walls[:, :2], walls[:, 2:]
    e = b - a
    rel = points[:, None, :] - a[None]
    k = np.clip(np.einsum("kmi,mi->km", rel, e) / np.einsum("mi,mi->m", e, e), 0.0, 1.0)
    nearest = a[None] + k[..., None] * e[None]
    return np.min(np.linalg.norm(points[:, None, :] - nearest, axis=2), axis=1)


def cross(u: np.ndarray, v: np.ndarray) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def test_the_registry_holds_exactly_the_documented_names() -> None:
    assert sorted(worlds.WORLDS) == sorted(NAMES)
    for name, spec in worlds.WORLDS.items():
        assert spec.name == name


def test_unknown_world_lists_the_names() -> None:
    with pytest.raises(UnknownWorldError, match="synthetic-office-loop") as info:
        worlds.load_world("synthetic-nowhere")
    assert isinstance(info.value, DatasetNotFoundError)


@pytest.mark.parametrize("name", QUICK)
def test_frames_follow_the_sequence_conventions(name: str) -> None:
    seq = worlds.load_world(name)
    spec = worlds.WORLDS[name]
    assert seq.name == name
    frames = list(seq)
    assert [f.index for f in frames] == list(range(len(frames)))
    first = frames[0]
    np.testing.assert_allclose(first.scan.angles, np.radians(np.arange(-90.0, 91.0)), atol=1e-12)
    assert first.scan.max_range == spec.laser.max_range
    np.testing.assert_array_equal(first.odometry, first.reference)  # odometry starts at the true pose
    ranges = np.array([f.scan.ranges for f in frames])
    finite = np.isfinite(ranges)
    assert np.all(ranges[finite] > 0) and np.all(ranges[finite] <= spec.laser.max_range)
    assert np.all(np.diff(seq.timestamps) > 0)
    np.testing.assert_array_equal(seq.reference, worlds.world_data(name).reference)
    np.testing.assert_array_equal(seq.odometry, worlds.world_data(name).odometry)


@pytest.mark.parametrize("name", QUICK)
def test_scans_are_the_walls_seen_from_the_reference_pose(name: str) -> None:
    """Every return, placed with the exact pose, lies on a wall (within the range noise)."""
    walls = worlds.world_geometry(name)
    sigma = worlds.WORLDS[name].laser.range_sigma
    for frame in list(worlds.load_world(name))[::97]:
        points = se2.transform_points(frame.reference, frame.scan.points())
        assert len(points) > 20
        assert float(np.max(point_to_walls(points, walls))) < 6 * sigma


def test_office_loop_is_a_closed_loop_of_the_documented_size() -> None:
    data = worlds.world_data("synthetic-office-loop")
    assert 1000 <= data.scans <= 2000
    assert 60.0 <= data.route_length <= 100.0
    np.testing.assert_array_equal(data.reference[0], data.reference[-1])
    steps = se2.relative_steps(data.reference)
    dist = np.hypot(steps[:, 0], steps[:, 1])
    turn = np.abs(steps[:, 2])
    full_move = (np.abs(dist - 0.1) < 1e-9) & (turn < 1e-12)
    short_move = (dist < 0.1) & (turn < 1e-12)  # the remainder at the end of a leg
    full_turn = (dist < 1e-12) & (np.abs(turn - math.radians(1)) < 1e-9)
    short_turn = (dist < 1e-12) & (turn < math.radians(1))
    assert np.all(full_move | short_move | full_turn | short_turn)
    assert np.count_nonzero(full_move) >= 780 and np.count_nonzero(full_turn) >= 1000


def test_office_startstop_is_about_a_hundred_views_in_metre_and_45_degree_steps() -> None:
    data = worlds.world_data("synthetic-office-startstop")
    assert data.scans == 106  # as many views as the thesis's Experiment 3
    steps = se2.relative_steps(data.reference)
    dist = np.hypot(steps[:, 0], steps[:, 1])
    turn = np.abs(steps[:, 2])
    moves = dist > 1e-12
    assert np.all(dist[moves] <= 1.0 + 1e-9) and np.count_nonzero(np.abs(dist[moves] - 1.0) < 1e-9) >= 70
    np.testing.assert_allclose(turn[~moves], math.radians(45.0), atol=1e-9)
    np.testing.assert_array_equal(data.reference[0], data.reference[-1])


def test_office_startstop_10deg_views_are_metre_moves_and_10_degree_turns() -> None:
    """Experiment 5's spacing: every step is a full 1 m move or 10 deg turn, or the one remainder of a leg."""
    data = worlds.world_data("synthetic-office-startstop-10deg")
    assert data.scans == 190
    steps = se2.relative_steps(data.reference)
    dist = np.hypot(steps[:, 0], steps[:, 1])
    turn = np.abs(steps[:, 2])
    moves = dist > 1e-12
    assert np.all(turn[moves] < 1e-12) and np.all(dist[~moves] < 1e-12)
    assert np.all(dist[moves] <= 1.0 + 1e-9) and np.all(turn[~moves] <= math.radians(10.0) + 1e-9)
    # Legs are cut into whole metres plus one remainder; the route turns by multiples of 90 deg only.
    legs = np.hypot(*np.diff(np.asarray(layouts.office_loop().waypoints), axis=0).T)
    assert np.count_nonzero(np.abs(dist[moves] - 1.0) < 1e-9) == int(np.floor(legs + 1e-9).sum()) == 77
    np.testing.assert_allclose(turn[~moves], math.radians(10.0), atol=1e-9)
    np.testing.assert_array_equal(data.reference[0], data.reference[-1])
    # Every pose of this world is a pose of the 0.1 m / 1 deg world: one route, two spacings.
    loop = worlds.world_data("synthetic-office-loop").reference
    nearest = np.min(np.linalg.norm(data.reference[:, None, :2] - loop[None, :, :2], axis=2), axis=1)
    assert float(nearest.max()) < 1e-9


def test_both_office_worlds_share_plan_and_route() -> None:
    loop = worlds.world_data("synthetic-office-loop")
    for name in ("synthetic-office-startstop", "synthetic-office-startstop-10deg"):
        startstop = worlds.world_data(name)
        np.testing.assert_array_equal(loop.plan.walls, startstop.plan.walls)
        assert loop.route_length == pytest.approx(startstop.route_length, abs=1e-9)
        assert [c.doorway for c in loop.crossings] == [c.doorway for c in startstop.crossings]


def test_corridor_shows_no_end_wall_until_it_comes_within_range() -> None:
    data = worlds.world_data("synthetic-corridor")
    seq = worlds.load_world("synthetic-corridor")
    max_range = worlds.WORLDS["synthetic-corridor"].laser.max_range
    assert data.crossings == () and len(data.plan.walls) == 4
    blind = 0
    for frame in seq:
        points = se2.transform_points(frame.reference, frame.scan.points())
        sees_end = bool(np.any(points[:, 0] > 60.0 - 0.05))
        # Only the two side walls (y = +-1) are in view until the end wall is within range.
        distance = 60.0 - frame.reference[0]
        if distance < max_range - 0.1:
            assert sees_end
        elif distance > max_range:
            assert not sees_end
        if not sees_end:
            assert np.all(np.abs(np.abs(points[:, 1]) - 1.0) < 0.06)
            blind += 1
    assert blind >= 250
    np.testing.assert_allclose(data.reference[:, 1:], 0.0)


def test_long_world_is_twenty_laps_of_the_loop_streamed_identically_twice() -> None:
    loop = worlds.world_data("synthetic-office-loop")
    long = worlds.world_data("synthetic-office-long")
    assert long.scans == 20 * (loop.scans - 1) + 1
    assert long.route_length == pytest.approx(20 * loop.route_length)
    np.testing.assert_array_equal(long.reference, repeat_laps(loop.reference, 20))
    assert len(long.crossings) == 20 * len(loop.crossings)
    seq = worlds.load_world("synthetic-office-long")
    assert sum(1 for _ in seq) == long.scans
    lap = loop.scans - 1
    frames = list(itertools.islice(seq, 4 * lap))
    again = list(itertools.islice(seq, 4 * lap))
    np.testing.assert_array_equal(np.array([f.scan.ranges for f in frames]), np.array([f.scan.ranges for f in again]))
    # Laps share the exact geometry, not the noise.
    a, b = frames[10].scan.ranges, frames[10 + 3 * lap].scan.ranges
    np.testing.assert_array_equal(frames[10].reference, frames[10 + 3 * lap].reference)
    assert not np.array_equal(a, b)
    assert float(np.nanmax(np.abs(a - b))) < 12 * worlds.WORLDS["synthetic-office-long"].laser.range_sigma


@pytest.mark.parametrize("name", QUICK)
def test_generation_is_deterministic(name: str) -> None:
    spec = worlds.WORLDS[name]
    a, b = worlds.generate(spec), worlds.generate(spec)
    for field in ("reference", "odometry", "timestamps", "lap_ranges"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    assert a.crossings == b.crossings
    first = [f.scan.ranges for f in worlds.load_world(name)]
    second = [f.scan.ranges for f in worlds.load_world(name)]
    np.testing.assert_array_equal(np.array(first), np.array(second))


def test_different_seeds_give_different_noise() -> None:
    loop = worlds.world_data("synthetic-office-loop")
    reseeded = worlds.generate(worlds.WorldSpec(**{**worlds.WORLDS["synthetic-office-loop"].__dict__, "seed": 1}))
    np.testing.assert_array_equal(loop.reference, reseeded.reference)
    assert not np.allclose(loop.odometry, reseeded.odometry)


def test_office_odometry_drifts_like_a_real_robot() -> None:
    for name in ("synthetic-office-loop", "synthetic-office-startstop", "synthetic-office-startstop-10deg"):
        data = worlds.world_data(name)
        gap = float(np.hypot(*(data.odometry[-1, :2] - data.reference[-1, :2])))
        assert 0.5 < gap < 5.0, name


def test_office_loop_crossings_lie_on_their_doorways_in_route_order() -> None:
    name = "synthetic-office-loop"
    data = worlds.world_data(name)
    crossings = worlds.doorway_crossings(name)
    assert [c.doorway for c in crossings] == [
        "office-sw-west",
        "office-sw-south",
        "kitchen",
        "kitchen",
        "lab-north",
        "lab-west",
    ]
    assert [(c.from_space, c.to_space) for c in crossings] == [
        ("corridor", "office-sw"),
        ("office-sw", "corridor"),
        ("corridor", "kitchen"),
        ("kitchen", "corridor"),
        ("corridor", "lab"),
        ("lab", "corridor"),
    ]
    for c in crossings:
        door = data.plan.doorway(c.doorway)
        a, b, p = np.array(door.a), np.array(door.b), np.array(c.position)
        e = b - a
        assert abs(cross(e, p - a)) < 1e-9 * float(np.linalg.norm(e))  # on the threshold line
        assert -1e-12 <= float(np.dot(p - a, e) / np.dot(e, e)) <= 1 + 1e-12  # between the jambs
        # The poses before and after the crossing are on the two sides of the threshold.
        before = cross(e, data.reference[c.scan - 1, :2] - a)
        after = cross(e, data.reference[c.scan, :2] - a)
        assert before * after <= 0 and before != 0
        # The route enters the crossing's destination space (first pose in a named space after it).
        ahead = (data.plan.space_at(*data.reference[k, :2]) for k in range(c.scan, data.scans))
        assert next(s for s in ahead if s is not None) == c.to_space


def test_route_keeps_clear_of_the_walls() -> None:
    data = worlds.world_data("synthetic-office-loop")
    clearance = point_to_walls(data.reference[:, :2], data.plan.walls)
    assert float(clearance.min()) >= 0.45 - 1e-9  # half a 0.9 m doorway


def test_metadata_carries_crossings_and_wall_count_as_json() -> None:
    for name in QUICK:
        seq = worlds.load_world(name)
        extra = seq.metadata.extra
        assert extra["world"] == name
        assert extra["wall_segments"] == len(worlds.world_geometry(name))
        assert extra["doorway_crossings"] == [c.as_dict() for c in worlds.doorway_crossings(name)]
        assert extra["laser"]["beams"] == 181 and extra["laser"]["resolution_deg"] == pytest.approx(1.0)
        json.dumps(extra)
        assert seq.metadata.format == "synthetic" and seq.metadata.reference_source


def test_summary_reports_the_world() -> None:
    summary = worlds.load_world("synthetic-office-startstop").summary()
    assert summary["scans"] == 106 and summary["beams"] == 181
    assert summary["has_reference"] is True and summary["relations"] == 0
    assert summary["duration_s"] > 0 and summary["odometry_path_m"] > 70.0


def test_world_geometry_is_a_copy() -> None:
    walls = worlds.world_geometry("synthetic-office-loop")
    assert walls.shape[1] == 4 and len(walls) > 50
    walls[:] = 0.0
    assert np.any(worlds.world_geometry("synthetic-office-loop") != 0.0)


def test_load_world_reuses_the_cached_generation() -> None:
    assert worlds.world_data("synthetic-corridor") is worlds.world_data("synthetic-corridor")
    lap = sample(worlds.WORLDS["synthetic-corridor"].route(), worlds.WORLDS["synthetic-corridor"].sampling)
    np.testing.assert_array_equal(worlds.load_world("synthetic-corridor").reference, lap)


def test_shared_beam_angles_are_read_only() -> None:
    frame = next(iter(worlds.load_world("synthetic-corridor")))
    with pytest.raises(ValueError):
        frame.scan.angles[0] = 1.0


def test_a_world_whose_route_crosses_a_wall_is_rejected() -> None:
    spec = worlds.WORLDS["synthetic-office-startstop"]
    bad = worlds.WorldSpec(**{**spec.__dict__, "route": lambda: Route(((1.0, 9.0), (12.0, 9.0)))})
    with pytest.raises(SyntheticWorldError, match="route leg 0"):
        worlds.generate(bad)
