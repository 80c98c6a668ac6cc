"""The odometry (dead-reckoning) baseline on a hand-made sequence with exact expectations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.model import Frame, Scan, Sequence
from albot1.methods.baselines.odometry import OdometryConfig, OdometryMapper
from albot1.methods.registry import resolve_config
from albot1.runs.execute import run_method

# Two beams 0.001 rad apart at 2.02 m: both points fall into the same 5 cm cell (away from its edges).
ANGLES = np.array([0.0, 0.001, 0.5])
RANGES = np.array([2.02, 2.02, np.nan])  # the third beam has no return

# Start at (1, 2) facing +y; drive 1.025 m forward; turn left while moving 1.025 m sideways; stand still.
ODOMETRY = np.array(
    [
        [1.0, 2.0, math.pi / 2],
        [1.0, 3.025, math.pi / 2],
        [-0.025, 3.025, math.pi],
        [-0.025, 3.025, math.pi],
    ]
)
# The same poses relative to the first one.
EXPECTED_POSES = np.array(
    [
        [0.0, 0.0, 0.0],
        [1.025, 0.0, 0.0],
        [1.025, 1.025, math.pi / 2],
        [1.025, 1.025, math.pi / 2],
    ]
)
# The beam at 0 rad, 2.02 m ahead, from each pose; scan 3 repeats scan 2's cells and adds nothing.
EXPECTED_POINTS = np.array([[2.02, 0.0], [3.045, 0.0], [1.025, 3.045]])


def _frames() -> list[Frame]:
    return [Frame(i, Scan(RANGES.copy(), ANGLES.copy(), float(i), 30.0), odo) for i, odo in enumerate(ODOMETRY)]


def _run(config: OdometryConfig) -> tuple[np.ndarray, np.ndarray, dict[str, int | float]]:
    mapper = OdometryMapper(config)
    for frame in _frames():
        mapper.process(frame)
    out = mapper.finish()
    assert out.map.points is not None
    return out.poses, out.map.points, out.counters


def test_poses_are_the_odometry_relative_to_the_first_scan() -> None:
    poses, _, _ = _run(OdometryConfig(map_voxel_m=0.05, map_every=1))
    np.testing.assert_allclose(poses, EXPECTED_POSES, atol=1e-12)


def test_map_is_every_scan_projected_and_thinned_first_point_wins() -> None:
    _, points, counters = _run(OdometryConfig(map_voxel_m=0.05, map_every=1))
    np.testing.assert_allclose(points, EXPECTED_POINTS, atol=1e-12)
    assert counters == {"views": 4, "updates": 4, "map_points": 3}


def test_map_every_projects_only_every_nth_scan() -> None:
    poses, points, counters = _run(OdometryConfig(map_voxel_m=0.05, map_every=2))
    np.testing.assert_allclose(poses, EXPECTED_POSES, atol=1e-12)  # poses for every scan regardless
    np.testing.assert_allclose(points, EXPECTED_POINTS[[0, 2]], atol=1e-12)
    assert counters["map_points"] == 2


def test_coarse_cells_merge_nearby_points() -> None:
    _, points, _ = _run(OdometryConfig(map_voxel_m=10.0, map_every=1))
    # All points lie in the cell [0, 10) x [0, 10): only the first is kept.
    np.testing.assert_allclose(points, [[2.02, 0.0]], atol=1e-12)


def test_runner_stores_degradation_free_odometry_and_counters() -> None:
    sequence = Sequence.from_frames("hand-made", _frames())
    result = run_method("odometry", sequence)
    np.testing.assert_allclose(result.poses, EXPECTED_POSES, atol=1e-12)
    np.testing.assert_array_equal(result.odometry, ODOMETRY)
    assert result.config == {"map_voxel_m": 0.05, "map_every": 1}
    assert result.counters["views"] == 4


def test_presets_come_from_the_toml_and_defaults_match_it() -> None:
    presets = OdometryMapper.presets
    assert presets["default"] == OdometryConfig().model_dump()
    assert resolve_config("odometry", "sparse-map") == OdometryConfig(map_every=10)


def test_env_and_overrides_follow_the_documented_precedence(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_ODOMETRY_MAP_EVERY", "3")
    assert resolve_config("odometry").map_every == 3  # type: ignore[attr-defined]
    assert resolve_config("odometry", "sparse-map").map_every == 3  # type: ignore[attr-defined]
    assert resolve_config("odometry", "sparse-map", {"map_every": "7"}).map_every == 7  # type: ignore[attr-defined]
