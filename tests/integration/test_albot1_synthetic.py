"""Albot1 on the embedded synthetic worlds: trajectory and map against the exact floor plan."""

from __future__ import annotations

import numpy as np
import pytest

from albot1.data.model import Frame, Sequence
from albot1.data.synthetic.worlds import load_world, world_geometry
from albot1.data.transforms import head
from albot1.geometry import se2
from albot1.runs.execute import run_method


def perfect_odometry(name: str) -> Sequence:
    """The world with its odometry replaced by the exact poses."""
    return load_world(name).with_frames(
        lambda frames: (Frame(f.index, f.scan, np.asarray(f.reference, dtype=float), f.reference) for f in frames)
    )


def distance_to_walls(points: np.ndarray, walls: np.ndarray) -> np.ndarray:
    a, ab = walls[:, :2], walls[:, 2:] - walls[:, :2]
    t = np.clip(((points[:, None, :] - a) * ab).sum(-1) / (ab * ab).sum(-1), 0.0, 1.0)
    return np.linalg.norm(a + t[..., None] * ab - points[:, None, :], axis=-1).min(axis=1)


@pytest.fixture(scope="module")
def office_run():
    seq = perfect_odometry("synthetic-office-loop")
    return run_method("albot1", seq, preset="exact"), np.asarray(load_world("synthetic-office-loop").reference)


def test_office_loop_with_perfect_odometry_tracks_the_route(office_run) -> None:
    result, reference = office_run
    truth = se2.between(reference[0], reference)
    err = np.hypot(*(result.poses[:, :2] - truth[:, :2]).T)
    heading = np.degrees(np.abs(se2.wrap(result.poses[:, 2] - truth[:, 2])))
    # The thesis's method drifts by design (single short landmarks give the heading at many
    # updates); on this 79 m loop it stays within a few percent of the distance travelled.
    length = se2.path_length(reference)
    assert length > 70.0
    assert err[:200].max() < 0.5
    assert err.mean() < 0.04 * length
    assert heading.max() < 15.0
    c = result.counters
    assert 0.2 <= c["updates"] / c["views"] <= 0.9
    assert c["path_integration"] < 0.2 * c["views"]


def test_office_loop_map_matches_the_floor_plan(office_run) -> None:
    result, reference = office_run
    walls = world_geometry("synthetic-office-loop")
    seg = result.map.segments
    assert len(seg) > 50
    # Map frame = the first view; the floor plan is in the reference frame.
    mids = se2.transform_points(reference[0], (seg[:, :2] + seg[:, 2:]) / 2.0)
    d = distance_to_walls(mids, walls)
    # Measured: 0.48 m without the beam-spacing test, 0.72 m with it (end_spacing_max_m = 0.2): the test halves
    # the aligned ATE (1.22 -> 0.69 m), but a heading error early in the loop leaves this unaligned map farther off.
    assert np.median(d) < 0.8


def test_albot1_plus_map_lies_on_the_floor_plan_with_perfect_odometry() -> None:
    # Albot1+ (docs/albot1-mapper.md, "Albot1+"): measured median 0.021 m, unaligned, over the whole loop.
    reference = np.asarray(load_world("synthetic-office-loop").reference)
    result = run_method("albot1", perfect_odometry("synthetic-office-loop"), preset="plus")
    seg = result.map.segments
    mids = se2.transform_points(reference[0], (seg[:, :2] + seg[:, 2:]) / 2.0)
    assert np.median(distance_to_walls(mids, world_geometry("synthetic-office-loop"))) < 0.05


def test_map_of_the_first_metres_lies_on_the_walls() -> None:
    # Before drift builds up, surface endpoints lie on the floor plan's walls.
    reference = np.asarray(load_world("synthetic-office-loop").reference)
    result = run_method("albot1", head(perfect_odometry("synthetic-office-loop"), 150), preset="exact")
    seg = result.map.segments
    assert len(seg) >= 10
    ends = se2.transform_points(reference[0], np.concatenate([seg[:, :2], seg[:, 2:]]))
    d = distance_to_walls(ends, world_geometry("synthetic-office-loop"))
    assert np.median(d) < 0.15
    assert (d < 0.4).mean() > 0.8


def test_featureless_corridor_falls_back_to_path_integration() -> None:
    result = run_method("albot1", perfect_odometry("synthetic-corridor"), preset="thesis")
    c = result.counters
    assert c["path_integration"] > 0
    assert np.isfinite(result.poses).all()
