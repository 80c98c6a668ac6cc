"""KISS-ICP baseline on the synthetic room: recovery of a known transform, a
noisy route, determinism, the planar projection and the fallback counters."""

from __future__ import annotations

import math
from typing import Any

import kiss_icp_room as room
import numpy as np

from albot1.contract import MapperOutput
from albot1.data.model import Frame, Scan
from albot1.geometry import se2
from albot1.methods.baselines.kiss_icp import KissIcpConfig, KissIcpMapper
from albot1.methods.registry import resolve_config


def _config(**overrides: Any) -> KissIcpConfig:
    config = resolve_config("kiss-icp", "default", overrides)
    assert isinstance(config, KissIcpConfig)
    return config


def _run(frames: list[Frame], **overrides: Any) -> MapperOutput:
    mapper = KissIcpMapper(_config(**overrides))
    for frame in frames:
        mapper.process(frame)
    return mapper.finish()


def _error(expected: np.ndarray, got: np.ndarray) -> tuple[float, float]:
    """Translation (m) and absolute rotation (deg) of ``inv(expected) * got``."""
    e = se2.between(expected, got)
    return math.hypot(e[0], e[1]), abs(math.degrees(e[2]))


def test_scan_pair_with_known_transform_is_recovered_within_1cm_and_0_1deg() -> None:
    a = np.array([1.0, 1.0, 0.3])
    b = np.array([1.4, 1.2, 0.4])
    # The odometry of the second scan is off by 8 cm, 5 cm and 2 deg: ICP must remove that.
    odo_b = se2.compose(b, [0.08, -0.05, math.radians(2.0)])
    out = _run([Frame(0, room.scan_at(a), a), Frame(1, room.scan_at(b), odo_b)])

    assert out.poses.shape == (2, 3)
    np.testing.assert_array_equal(out.poses[0], [0.0, 0.0, 0.0])
    shift, turn = _error(se2.between(a, b), out.poses[1])
    assert shift < 0.01
    assert turn < 0.1
    # The odometry alone is outside that tolerance, so the test measures the registration.
    odo_shift, odo_turn = _error(se2.between(a, b), se2.between(a, odo_b))
    assert odo_shift > 0.05 and odo_turn > 1.0


def test_noisy_route_stays_within_centimetres_while_odometry_drifts() -> None:
    truth = room.route(30)
    odometry = room.noisy_odometry(truth, sigma_xy=0.05, sigma_deg=2.0, seed=3)
    out = _run(room.frames(truth, odometry))

    estimate = se2.compose(truth[0], out.poses)  # the method's frame starts at the first scan
    errors = [_error(t, e) for t, e in zip(truth, estimate)]
    odo_errors = [_error(t, o) for t, o in zip(truth, odometry)]
    assert max(e[0] for e in errors) < 0.03
    assert max(e[1] for e in errors) < 0.5
    assert max(e[0] for e in odo_errors) > 0.3
    assert out.counters["views"] == 30
    assert out.counters["updates"] == 30
    assert out.counters["registrations"] == 29
    assert out.counters["registration_failures"] == 0
    assert out.counters["odometry_fallbacks"] == 0
    assert out.counters["map_points"] == len(out.map.points)
    assert out.extras["kiss_icp"]["correction_m"]["n"] == 29


def test_same_input_twice_gives_identical_poses_and_map() -> None:
    truth = room.route(12)
    frames = room.frames(truth, room.noisy_odometry(truth, 0.05, 2.0, seed=1), beams=360)
    first, second = _run(frames), _run(frames)
    np.testing.assert_array_equal(first.poses, second.poses)
    assert first.map.points is not None and second.map.points is not None
    np.testing.assert_array_equal(first.map.points, second.map.points)
    assert first.counters == second.counters


def test_poses_are_planar_and_the_removed_out_of_plane_part_is_reported() -> None:
    truth = room.route(8)
    out = _run(room.frames(truth, truth, beams=360))
    assert out.extras["kiss_icp"]["max_out_of_plane_removed"] < 1e-9
    assert np.all(np.abs(out.poses[:, 2]) <= math.pi)


def test_scans_enter_the_voxel_map_only_after_enough_motion() -> None:
    truth = room.route(20)
    out = _run(room.frames(truth, truth, beams=360), map_update_distance_m=1.0, map_update_angle_deg=90.0)
    inserted, expected = out.poses[0], 1
    for pose in out.poses[1:]:
        step = se2.between(inserted, pose)
        if math.hypot(step[0], step[1]) >= 1.0 or abs(step[2]) >= math.radians(90.0):
            inserted, expected = pose, expected + 1
    assert 3 < expected < 20
    assert out.counters["updates"] == expected
    every = _run(room.frames(truth, truth, beams=360), map_update_distance_m=0.0, map_update_angle_deg=0.0)
    assert every.counters["updates"] == 20


def test_scan_with_too_few_points_keeps_the_odometry_prediction() -> None:
    a = np.array([1.0, 1.0, 0.0])
    b = np.array([1.5, 1.1, 0.1])
    empty = Scan(np.full(180, np.nan), np.linspace(-math.pi / 2, math.pi / 2, 180), 0.1, 30.0)
    out = _run([Frame(0, room.scan_at(a), a), Frame(1, empty, b)])
    np.testing.assert_allclose(out.poses[1], se2.between(a, b), atol=1e-12)
    assert out.counters["odometry_fallbacks"] == 1
    assert out.counters["registrations"] == 0
    assert out.counters["updates"] == 1  # nothing to insert from an empty scan
    assert out.extras["kiss_icp"]["fallback_scans"] == [1]


def test_range_limits_drop_beams_outside_them() -> None:
    pose = np.array([1.0, 1.0, 0.0])
    near = _run([Frame(0, room.scan_at(pose), pose)], max_range_m=2.0)
    full = _run([Frame(0, room.scan_at(pose), pose)])
    assert near.map.points is not None and full.map.points is not None
    assert 0 < len(near.map.points) < len(full.map.points)
    assert np.hypot(*near.map.points.T).max() <= 2.0


def test_sensor_offset_is_applied_by_the_runner_not_the_mapper() -> None:
    from albot1.data.model import Sequence, SequenceMetadata
    from albot1.runs.execute import run_method

    pose = np.array([4.0, 3.0, 0.0])
    scan = room.scan_at(pose)
    # The same scan declared as taken by a laser 0.5 m ahead of the base: the method works in the laser's frame
    # (the map is the scan as measured), and the robot pose it reports is 0.5 m behind the laser.
    base = run_method(
        "kiss-icp", Sequence.from_frames("base", [Frame(0, scan, pose)]), overrides={"map_voxel_m": 0.001}
    )
    ahead = run_method(
        "kiss-icp",
        Sequence.from_frames("ahead", [Frame(0, scan, pose)], SequenceMetadata(sensor_offset=(0.5, 0.0, 0.0))),
        overrides={"map_voxel_m": 0.001},
    )
    assert base.map.points is not None and ahead.map.points is not None
    np.testing.assert_allclose(ahead.map.points, base.map.points, atol=1e-12)
    np.testing.assert_allclose(ahead.poses[0], [-0.5, 0.0, 0.0], atol=1e-12)
    assert "sensor_offset_x_m" not in KissIcpConfig.model_fields


def test_constant_velocity_model_ignores_the_odometry() -> None:
    truth = room.route(6)
    # odometry_prior = false is KISS-ICP's own constant-velocity prediction: the odometry plays no part.
    frozen = np.repeat(truth[:1], len(truth), axis=0)
    with_truth = _run(room.frames(truth, truth, beams=360), odometry_prior=False)
    with_frozen = _run(room.frames(truth, frozen, beams=360), odometry_prior=False)
    np.testing.assert_array_equal(with_truth.poses, with_frozen.poses)
    with_prior = _run(room.frames(truth, frozen, beams=360))
    assert not np.array_equal(with_prior.poses, with_frozen.poses)
