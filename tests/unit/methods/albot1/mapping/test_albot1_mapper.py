"""Algorithm 4 (the main loop) and the mapper's contract: branches, degenerate input, frames, counters."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest

from albot1.data.model import Frame, Scan, Sequence
from albot1.data.synthetic.lidar import cast
from albot1.geometry import se2
from albot1.methods.albot1.mapping import mapper as mapper_module
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.errors import MappingError
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.perception.landmarks import CORNER
from albot1.methods.albot1.perception.view import View
from albot1.runs.execute import run_method

ANGLES = np.radians(np.arange(-90.0, 91.0, 1.0))
ROOM = np.array(
    [
        [-1.0, -2.0, 6.0, -2.0],
        [6.0, -2.0, 6.0, 3.0],
        [6.0, 3.0, -1.0, 3.0],
        [2.5, 0.8, 3.2, 0.8],
        [3.2, 0.8, 3.2, 1.4],
        [3.2, 1.4, 2.5, 1.4],
        [2.5, 1.4, 2.5, 0.8],
    ]
)

# Hand-made landmarks (thesis frame), 1 m long, both ends corners, far apart.
LANDMARKS = {name: np.array([x, 4.0, x + 1.0, 4.0]) for name, x in zip("ABCDE", (-6.0, -4.0, -2.0, 0.0, 2.0))}


def hand_view(names: str) -> View:
    segs = np.array([LANDMARKS[c] for c in names]).reshape(-1, 4)
    kinds = np.full((len(names), 2), CORNER, dtype=np.int64)
    return View(segs, kinds, np.zeros((len(names), 2), dtype=np.int64), np.arange(len(names), dtype=np.int64))


def blank_frame(i: int, odometry=(0.0, 0.0, 0.0)) -> Frame:
    return Frame(
        i, Scan(np.full(3, np.nan), np.array([-1.0, 0.0, 1.0]), float(i), 30.0), np.asarray(odometry, dtype=float)
    )


def run_views(monkeypatch: pytest.MonkeyPatch, sequence: list[str], **config) -> Albot1Mapper:
    views: Iterator[View] = iter(hand_view(names) for names in sequence)
    monkeypatch.setattr(mapper_module, "construct_view", lambda *args, **kwargs: next(views))
    mapper = Albot1Mapper(Albot1Config(**config))
    for i in range(len(sequence)):
        mapper.process(blank_frame(i))
    return mapper


def test_algorithm_4_branches_on_a_hand_made_landmark_sequence(monkeypatch: pytest.MonkeyPatch) -> None:
    seq = ["ABCD", "ABC", "AB", "AB", "ABCD", "ABCD", "ABCD", "", "E"]
    out = run_views(monkeypatch, seq).finish()
    trace = [(t["scan"], t["view"], t["view_scan"], t["pose_source"]) for t in out.extras["update_trace"]]
    assert trace == [
        (0, "initial", 0, "initial"),
        # 2 of 3 recognised two steps after the last update: update with the previous view,
        # recognise again against its landmarks, still 2: update with the current view too.
        (2, "previous", 1, "stored"),
        (2, "current", 2, "landmark"),
        # One step after an update: update with the current view.
        (3, "current", 3, "landmark"),
        (4, "current", 4, "landmark"),
        # Nothing recognised: previous view, then the current one placed by path integration.
        (7, "previous", 6, "stored"),
        (7, "current", 7, "odometry"),
        (8, "current", 8, "odometry"),
    ]
    assert out.extras["landmarks_recognised"] == [0, 3, 2, 2, 2, 4, 4, 0, 0]
    c = out.counters
    assert (c["views"], c["updates"], c["updates_current_view"], c["updates_previous_view"]) == (9, 7, 5, 2)
    assert (c["double_updates"], c["path_integration"], c["stationary_steps"]) == (2, 2, 8)
    assert c["empty_views"] == 1 and c["single_surface_views"] == 1
    np.testing.assert_allclose(out.poses, 0.0, atol=1e-12)


def test_a_lower_update_threshold_changes_the_branches(monkeypatch: pytest.MonkeyPatch) -> None:
    out = run_views(monkeypatch, ["ABCD", "ABC", "AB", "AB"], min_landmarks=2).finish()
    assert [t["scan"] for t in out.extras["update_trace"]] == [0]


def update_trace(out) -> list[tuple[int, str, int]]:
    return [(t["scan"], t["view"], t["view_scan"]) for t in out.extras["update_trace"]]


def test_the_update_rule_counts_the_recognised_landmarks_not_those_in_view(monkeypatch: pytest.MonkeyPatch) -> None:
    # Section 3.1 defines the limiting point as "a view that contains less than three landmark surfaces"; Algorithm 4
    # line 12 tests "(RL_n).size < 3", the landmarks recognised from the tracked list: the code reads line 12. View 1
    # holds four landmarks but only A and B were tracked: an update (one step after the last: the current view).
    out = run_views(monkeypatch, ["ABC", "ABDE"]).finish()
    assert out.extras["landmarks_recognised"] == [0, 2]
    assert update_trace(out) == [(0, "initial", 0), (1, "current", 1)]
    # Exactly three recognised (of five in view): no update.
    out = run_views(monkeypatch, ["ABC", "ABCDE"]).finish()
    assert out.extras["landmarks_recognised"] == [0, 3]
    assert update_trace(out) == [(0, "initial", 0)]


def test_after_a_previous_view_update_three_recognised_again_need_no_second_update(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Scan 1 recognises A, B, C (exactly 3: no update) and is left tracking them, though it saw D and E too. Scan 2
    # sees C, D, E: one recognised, two steps after the last update, so lines 18-22 update the map with view 1 and
    # reset the list to view 1's landmarks (A-E); line 23 ("Go back to step 11") recognises C, D, E from it: three,
    # not fewer, so line 12 asks for no second update.
    out = run_views(monkeypatch, ["ABC", "ABCDE", "CDE"]).finish()
    assert out.extras["landmarks_recognised"] == [0, 3, 1]
    assert update_trace(out) == [(0, "initial", 0), (2, "previous", 1)]
    c = out.counters
    assert (c["updates"], c["updates_previous_view"], c["updates_current_view"], c["double_updates"]) == (1, 1, 0, 0)
    # The same with D missing from scan 2: two recognised after the reset, so the current view is added too.
    out = run_views(monkeypatch, ["ABC", "ABCDE", "CE"]).finish()
    assert update_trace(out) == [(0, "initial", 0), (2, "previous", 1), (2, "current", 2)]
    assert out.counters["double_updates"] == 1


def room_frames(poses: np.ndarray, walls: np.ndarray = ROOM) -> list[Frame]:
    return [
        Frame(i, Scan(cast(walls, p, ANGLES, 30.0), ANGLES, float(i), 30.0), np.asarray(p, dtype=float))
        for i, p in enumerate(poses)
    ]


def run_frames(frames: list[Frame], **config):
    mapper = Albot1Mapper(Albot1Config(**config))
    for f in frames:
        mapper.process(f)
    return mapper.finish()


def test_poses_and_map_come_out_in_a_rep103_map_frame() -> None:
    # Start at an arbitrary odometry pose; the output starts at the origin with heading 0.
    start = np.array([10.0, -4.0, 0.5])
    steps = np.array([[0.1 * k, 0.0, 0.0] for k in range(11)])
    odom = se2.compose(start, steps)
    world = se2.compose(np.zeros(3), steps)
    frames = [Frame(f.index, room_frames(world[i : i + 1])[0].scan, odom[i]) for i, f in enumerate(room_frames(world))]
    out = run_frames(frames, motion_model="exact")
    np.testing.assert_allclose(out.poses[0], 0.0, atol=1e-12)
    np.testing.assert_allclose(out.poses[-1], [1.0, 0.0, 0.0], atol=0.05)
    seg = out.map.segments
    # The far wall x = 6 (REP) appears as a vertical segment at x = 6 in the map frame.
    vertical = np.abs(seg[:, 0] - seg[:, 2]) < 0.05
    assert np.any(vertical & (np.abs(seg[:, 0] - 6.0) < 0.1))
    props = out.map.segment_properties
    assert len(props) == len(seg) and all(p["history"][0]["event"] == "added" for p in props)


def test_degenerate_input_never_crashes_and_is_counted() -> None:
    steps = [np.array([0.1 * k, 0.0, 0.0]) for k in range(5)]
    steps += [steps[-1].copy() for _ in range(30)]  # 30 stationary steps
    steps += [steps[-1] + np.array([6.0, 0.0, 0.0])]  # a 6 m odometry jump
    steps += [steps[-1] + np.array([0.1 * k, 0.0, 0.0]) for k in range(1, 4)]
    poses = np.array(steps)
    frames = room_frames(np.minimum(poses, [0.4, 0.0, 0.0]))
    frames = [Frame(f.index, f.scan, poses[f.index]) for f in frames]
    # Scans with no returns, then a view of a single wall.
    n = len(frames)
    nan_scan = Scan(np.full(ANGLES.shape, np.nan), ANGLES, 0.0, 30.0)
    frames += [Frame(n + k, nan_scan, poses[-1] + [0.1 * (k + 1), 0, 0]) for k in range(4)]
    wall = cast(np.array([[2.0, -1.0, 2.0, 1.0]]), np.zeros(3), ANGLES, 30.0)
    frames += [Frame(n + 4 + k, Scan(wall, ANGLES, 0.0, 30.0), poses[-1] + [0.5 + 0.1 * k, 0, 0]) for k in range(3)]
    out = run_frames(frames)
    c = out.counters
    assert out.poses.shape == (len(frames), 3) and np.isfinite(out.poses).all()
    assert c["stationary_steps"] == 30
    assert c["odometry_jumps"] == 1
    assert c["empty_views"] == 4
    assert c["single_surface_views"] == 3
    assert c["path_integration"] >= 1
    # Standing still in front of the same landmarks keeps the pose exactly (from the second
    # still step: the first may rank the landmarks differently, gaps being floored now).
    np.testing.assert_allclose(out.poses[6:35], np.repeat(out.poses[5:6], 29, axis=0), atol=1e-9)
    np.testing.assert_allclose(out.poses[5], [0.4, 0.0, 0.0], atol=0.05)


def test_first_scan_without_returns_and_bad_odometry() -> None:
    frames = [
        Frame(i, Scan(np.full(ANGLES.shape, np.nan), ANGLES, 0.0, 30.0), np.array([0.1 * i, 0.0, 0.0]))
        for i in range(3)
    ]
    out = run_frames(frames)
    np.testing.assert_allclose(out.poses[:, 0], [0.0, 0.1, 0.2], atol=1e-12)
    mapper = Albot1Mapper(Albot1Config())
    with pytest.raises(MappingError, match="scan 7: odometry"):
        mapper.process(Frame(7, frames[0].scan, np.array([0.0, math.nan, 0.0])))


def test_the_generic_runner_runs_both_presets() -> None:
    poses = np.array([[0.05 * k, 0.0, math.radians(0.5 * k)] for k in range(20)])
    seq = Sequence.from_frames("room", room_frames(poses))
    for preset in ("thesis", "exact", "default"):
        result = run_method("albot1", seq, preset=preset)
        assert result.counters["views"] == 20 and result.poses.shape == (20, 3)
        assert result.config["motion_model"] == ("exact" if preset == "exact" else "thesis")
