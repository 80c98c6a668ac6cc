"""Route sampling: continuous and start-stop spacing, turns on the spot, exact closure, timestamps, laps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.synthetic.errors import SyntheticWorldError
from albot1.data.synthetic.route import CONTINUOUS, START_STOP, Route, Sampling, repeat_laps, sample, timestamps
from albot1.geometry import se2

RECTANGLE = Route(((0.0, 0.0), (5.5, 0.0), (5.5, 3.0), (0.0, 3.0), (0.0, 0.0)), closed=True)


def test_start_stop_moves_in_whole_metres_and_turns_in_45_degree_steps() -> None:
    poses = sample(RECTANGLE, START_STOP)
    steps = se2.relative_steps(poses)
    # 5.5 m -> 5 x 1 m + 0.5 m; 3 m -> 3 x 1 m; four left turns of 90 deg -> 8 x 45 deg.
    assert len(poses) == 1 + (6 + 3 + 6 + 3) + 8
    np.testing.assert_allclose(steps[:6], [[1, 0, 0]] * 5 + [[0.5, 0, 0]], atol=1e-12)
    np.testing.assert_allclose(steps[6:8], [[0, 0, math.pi / 4]] * 2, atol=1e-12)
    np.testing.assert_allclose(poses[6], [5.5, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(poses[8], [5.5, 0.0, math.pi / 2], atol=1e-12)


def test_continuous_takes_a_scan_every_tenth_of_a_metre_or_degree() -> None:
    poses = sample(RECTANGLE, CONTINUOUS)
    steps = se2.relative_steps(poses)
    moving = np.hypot(steps[:, 0], steps[:, 1]) > 1e-12
    turning = np.abs(steps[:, 2]) > 1e-12
    assert not np.any(moving & turning)  # turns are on the spot
    np.testing.assert_allclose(np.hypot(steps[moving, 0], steps[moving, 1]), 0.1, atol=1e-9)
    np.testing.assert_allclose(np.abs(steps[turning, 2]), math.radians(1.0), atol=1e-9)
    assert np.count_nonzero(moving) == 170  # 17 m
    assert np.count_nonzero(turning) == 360  # four 90 deg turns
    np.testing.assert_allclose(steps[moving, 1], 0.0, atol=1e-12)  # always driving forward


def test_a_closed_route_ends_exactly_where_and_as_it_started() -> None:
    for sampling in (CONTINUOUS, START_STOP):
        poses = sample(RECTANGLE, sampling)
        np.testing.assert_array_equal(poses[-1], poses[0])


def test_half_turns_go_clockwise_and_headings_stay_wrapped() -> None:
    poses = sample(Route(((0.0, 0.0), (2.0, 0.0), (0.0, 0.0))), START_STOP)
    steps = se2.relative_steps(poses)
    np.testing.assert_allclose(steps[2:6, 2], -math.pi / 4, atol=1e-12)
    assert np.all((poses[:, 2] >= -math.pi) & (poses[:, 2] < math.pi))
    np.testing.assert_allclose(poses[-1, :2], [0.0, 0.0], atol=1e-12)


def test_start_and_end_headings() -> None:
    route = Route(((0.0, 0.0), (0.0, 2.0)), start_heading=0.0, end_heading=math.pi)
    poses = sample(route, START_STOP)
    np.testing.assert_allclose(poses[0], [0.0, 0.0, 0.0])
    np.testing.assert_allclose(poses[2], [0.0, 0.0, math.pi / 2], atol=1e-12)  # turned left first
    assert float(se2.wrap(poses[-1, 2] - math.pi)) == pytest.approx(0.0, abs=1e-12)
    assert route.length == pytest.approx(2.0)


def test_poses_lie_on_the_legs() -> None:
    route = Route(((0.0, 0.0), (3.0, 4.0), (3.0, -1.0)))
    poses = sample(route, CONTINUOUS)
    first_leg = poses[:51]
    np.testing.assert_allclose(first_leg[:, 1], first_leg[:, 0] * 4.0 / 3.0, atol=1e-12)
    np.testing.assert_allclose(poses[50, :2], [3.0, 4.0], atol=1e-12)
    np.testing.assert_allclose(poses[-1, :2], [3.0, -1.0], atol=1e-12)


def test_timestamps_follow_constant_speeds_plus_dwell() -> None:
    poses = sample(RECTANGLE, START_STOP)
    t = timestamps(poses, START_STOP, start=10.0)
    assert t[0] == 10.0
    dt = np.diff(t)
    np.testing.assert_allclose(dt[:5], 1.0 / 0.5 + 1.0)  # 1 m at 0.5 m/s, then a 1 s stop
    np.testing.assert_allclose(dt[5], 0.5 / 0.5 + 1.0)
    np.testing.assert_allclose(dt[6], 1.0 + 1.0)  # 45 deg at 45 deg/s
    fast = timestamps(sample(RECTANGLE, CONTINUOUS), CONTINUOUS)
    assert np.all(np.diff(fast) > 0)
    assert set(np.round(np.diff(fast), 9)) == {0.2, round(1.0 / 45.0, 9)}


def test_laps_repeat_the_lap_with_one_shared_pose_between_laps() -> None:
    lap = sample(RECTANGLE, START_STOP)
    three = repeat_laps(lap, 3)
    assert len(three) == 3 * (len(lap) - 1) + 1
    np.testing.assert_array_equal(three[: len(lap)], lap)
    np.testing.assert_array_equal(three[len(lap) - 1 : 2 * len(lap) - 1], lap)
    np.testing.assert_array_equal(repeat_laps(lap, 1), lap)
    with pytest.raises(SyntheticWorldError, match="closed"):
        repeat_laps(sample(Route(((0.0, 0.0), (1.0, 0.0))), START_STOP), 2)
    with pytest.raises(SyntheticWorldError, match="at least 1 lap"):
        repeat_laps(lap, 0)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"waypoints": ((0.0, 0.0),)}, "at least 2 waypoints"),
        ({"waypoints": ((0.0, 0.0), (1.0, 0.0)), "closed": True}, "must end at its first waypoint"),
        ({"waypoints": ((0.0, 0.0), (1.0, 0.0), (1.0, 0.0))}, "waypoints 1 and 2 coincide"),
    ],
)
def test_bad_routes(kwargs, message) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(SyntheticWorldError, match=message):
        Route(**kwargs)


@pytest.mark.parametrize("field", ["step_m", "step_deg", "speed_mps", "turn_rate_dps"])
def test_bad_sampling(field: str) -> None:
    values = {"step_m": 0.1, "step_deg": 1.0, field: 0.0}
    with pytest.raises(SyntheticWorldError, match=field):
        Sampling(**values)
    with pytest.raises(SyntheticWorldError, match="dwell"):
        Sampling(0.1, 1.0, dwell_s=-1.0)
