"""The KISS-ICP baseline's failure paths: NaN input, a registration that
diverges, and registrations that keep contradicting the odometry."""

from __future__ import annotations

import math
from typing import Any

import kiss_icp_room as room
import numpy as np
import pytest

from albot1.data.model import Frame, Sequence
from albot1.geometry import se2
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.kiss_icp import KissIcpConfig, KissIcpMapper
from albot1.methods.registry import resolve_config
from albot1.runs.execute import run_method


def _mapper(**overrides: Any) -> KissIcpMapper:
    config = resolve_config("kiss-icp", "default", overrides)
    assert isinstance(config, KissIcpConfig)
    return KissIcpMapper(config)


class _FixedResult:
    """Stands in for KISS-ICP's Registration and returns a given 4x4 matrix."""

    def __init__(self, matrix: np.ndarray) -> None:
        self.matrix = matrix

    def align_points_to_map(self, **_: Any) -> np.ndarray:
        return self.matrix


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_non_finite_odometry_names_the_scan(bad: float) -> None:
    mapper = _mapper()
    pose = np.array([1.0, 1.0, 0.0])
    mapper.process(Frame(0, room.scan_at(pose), pose))
    with pytest.raises(BaselineError, match=r"kiss-icp: scan 1: odometry .* is not a finite"):
        mapper.process(Frame(1, room.scan_at(pose), np.array([1.0, bad, 0.0])))


def test_nan_ranges_are_no_returns_not_errors() -> None:
    pose = np.array([1.0, 1.0, 0.0])
    scan = room.scan_at(pose)
    assert np.isnan(scan.ranges).sum() == 0
    ranges = scan.ranges.copy()
    ranges[::3] = np.nan
    holey = type(scan)(ranges, scan.angles, scan.timestamp, scan.max_range)
    mapper = _mapper()
    mapper.process(Frame(0, scan, pose))
    mapper.process(Frame(1, holey, pose))
    out = mapper.finish()
    assert np.isfinite(out.poses).all()
    assert out.counters["registration_failures"] == 0


def test_non_finite_registration_result_is_a_divergence_error() -> None:
    mapper = _mapper()
    mapper._registration = _FixedResult(np.full((4, 4), np.nan))  # type: ignore[assignment]
    pose = np.array([1.0, 1.0, 0.0])
    mapper.process(Frame(0, room.scan_at(pose), pose))
    with pytest.raises(BaselineError, match=r"kiss-icp diverged at scan 1: .*non-finite pose"):
        mapper.process(Frame(1, room.scan_at(pose), pose))


def test_registration_far_from_the_odometry_falls_back_then_raises() -> None:
    mapper = _mapper(max_consecutive_failures=2)
    # Every registration "moves" the robot 5 m from where odometry puts it.
    mapper._registration = _FixedResult(np.array([[1.0, 0, 0, 5.0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]))
    pose = np.array([1.0, 1.0, 0.0])
    for i in range(3):
        mapper.process(Frame(i, room.scan_at(pose), pose))
    assert mapper._counters["registration_failures"] == 2
    assert mapper._counters["odometry_fallbacks"] == 2
    with pytest.raises(BaselineError, match=r"kiss-icp lost track at scan 3: 3 consecutive registrations"):
        mapper.process(Frame(3, room.scan_at(pose), pose))


def test_real_registration_that_contradicts_the_odometry_is_rejected() -> None:
    """Odometry claims the robot stood still while it moved 0.4 m: ICP finds the move, the bound rejects it."""
    a = np.array([3.5, 1.5, 0.2])
    b = se2.compose(a, [0.4, 0.0, 0.0])
    frames = [Frame(0, room.scan_at(a), a), Frame(1, room.scan_at(b), a)]
    loose = _mapper(fixed_threshold_m=0.3, voxel_size_m=0.5)
    for frame in frames:
        loose.process(frame)
    moved = loose.finish().poses[1]
    assert math.hypot(moved[0], moved[1]) == pytest.approx(0.4, abs=0.02)  # ICP does recover the move...

    strict = _mapper(fixed_threshold_m=0.3, voxel_size_m=0.5, max_correction_m=0.2, max_consecutive_failures=0)
    strict.process(frames[0])
    with pytest.raises(BaselineError, match=r"lost track at scan 1: .*more than 0.2 m"):
        strict.process(frames[1])  # ...which is more than this config lets a correction be


def test_runner_error_names_method_dataset_and_scan() -> None:
    pose = np.array([1.0, 1.0, 0.0])
    frames = [Frame(0, room.scan_at(pose, 180), pose), Frame(1, room.scan_at(pose, 180), np.array([np.nan, 0, 0]))]
    sequence = Sequence.from_frames("nan-odometry", frames)
    with pytest.raises(BaselineError, match=r"^kiss-icp on nan-odometry: scan 1: odometry \[nan, 0.0, 0.0\] is not"):
        run_method("kiss-icp", sequence)
