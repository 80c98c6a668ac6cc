"""Property tests of the synthetic-world geometry: ray casting against a brute-force reference, route sampling."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from albot1.data.synthetic.lidar import cast
from albot1.data.synthetic.route import Route, Sampling, sample
from albot1.geometry import se2

COORD = st.floats(-20.0, 20.0, allow_nan=False, allow_infinity=False)
ANGLES = np.radians(np.arange(-90.0, 91.0))


def brute_force(walls: np.ndarray, pose: np.ndarray, angles: np.ndarray, slack: float) -> np.ndarray:
    """Nearest hit per beam, every beam against every wall, hits accepted for u in [-slack, 1 + slack]."""
    out = np.full(len(angles), np.inf)
    for i, angle in enumerate(angles):
        d = np.array([math.cos(pose[2] + angle), math.sin(pose[2] + angle)])
        for x1, y1, x2, y2 in walls:
            e = np.array([x2 - x1, y2 - y1])
            w = np.array([x1 - pose[0], y1 - pose[1]])
            den = d[0] * e[1] - d[1] * e[0]
            if den == 0:
                continue
            t = (w[0] * e[1] - w[1] * e[0]) / den
            u = (w[0] * d[1] - w[1] * d[0]) / den
            if t > 1e-9 and -slack <= u <= 1 + slack:
                out[i] = min(out[i], t)
    return out


def distance_to_walls(walls: np.ndarray, x: float, y: float) -> float:
    """The distance from (x, y) to the nearest point of any wall (a degenerate wall is its end point)."""
    start, end = walls[:, :2], walls[:, 2:]
    along = end - start
    length2 = np.einsum("ij,ij->i", along, along)
    safe = np.where(length2 > 0.0, length2, 1.0)
    u = np.where(length2 > 0.0, np.clip(np.einsum("ij,ij->i", np.array([x, y]) - start, along) / safe, 0.0, 1.0), 0.0)
    nearest = start + u[:, None] * along
    return float(np.min(np.hypot(nearest[:, 0] - x, nearest[:, 1] - y)))


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(COORD, COORD, COORD, COORD), min_size=1, max_size=8), COORD, COORD, st.floats(-math.pi, math.pi)
)
def test_ranges_agree_with_brute_force(
    segments: list[tuple[float, float, float, float]], x: float, y: float, heading: float
) -> None:
    walls = np.array(segments)
    # The sensor is never placed on a wall (albot1.data.synthetic.lidar): from a point on a wall, a beam along it
    # has no defined range (found by hypothesis: a pose 2e-16 m from a wall's end, a beam along the wall).
    assume(distance_to_walls(walls, x, y) > 1e-6)
    pose = np.array([x, y, heading])
    got = cast(walls, pose, ANGLES, 30.0)
    got = np.where(np.isnan(got), np.inf, got)
    # The fast cast is sandwiched between a brute force that accepts slightly more of each wall
    # (nearest possible) and one that accepts slightly less (farthest possible); they differ only
    # for rays that graze a wall's end point.
    loose = brute_force(walls, pose, ANGLES, 1e-6)
    strict = brute_force(walls, pose, ANGLES, -1e-6)
    loose = np.where(loose <= 30.0, loose, np.inf)
    strict = np.where(strict <= 30.0, strict, np.inf)
    scale = 1e-7 * (1.0 + np.where(np.isfinite(strict), strict, 0.0))
    assert np.all((got >= loose - scale) | ~np.isfinite(loose))
    assert np.all((got <= strict + scale) | ~np.isfinite(strict))


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.tuples(COORD, COORD, COORD, COORD), min_size=1, max_size=6),
    COORD,
    COORD,
    st.floats(-math.pi, math.pi),
    st.floats(-math.pi, math.pi),
    COORD,
    COORD,
)
def test_moving_the_world_with_the_robot_changes_nothing(
    segments: list[tuple[float, float, float, float]],
    x: float,
    y: float,
    heading: float,
    turn: float,
    dx: float,
    dy: float,
) -> None:
    walls = np.array(segments)
    # A ray running exactly along a zero-thickness wall is degenerate (a real wall's end face would be
    # hit); keep the sensor off every wall's line so no beam can be collinear with a wall.
    e = walls[:, 2:] - walls[:, :2]
    length = np.hypot(e[:, 0], e[:, 1])
    offset = np.abs(e[:, 0] * (y - walls[:, 1]) - e[:, 1] * (x - walls[:, 0]))
    assume(bool(np.all((length > 1e-3) & (offset > 1e-3 * length))))
    motion = np.array([dx, dy, turn])
    moved = np.hstack([se2.transform_points(motion, walls[:, :2]), se2.transform_points(motion, walls[:, 2:])])
    a = cast(walls, [x, y, heading], ANGLES, 30.0)
    b = cast(moved, se2.compose(motion, [x, y, heading]), ANGLES, 30.0)
    both = np.isfinite(a) & np.isfinite(b)
    np.testing.assert_allclose(a[both], b[both], rtol=1e-6, atol=1e-6)
    # Beams may only disagree on existence where a ray grazes an end point or the max range.
    assert np.count_nonzero(np.isfinite(a) != np.isfinite(b)) <= 2


GRID = st.integers(-10, 10).map(float)


@settings(max_examples=80, deadline=None)
@given(
    st.lists(st.tuples(GRID, GRID), min_size=2, max_size=6, unique=True),
    st.sampled_from([(0.1, 1.0), (1.0, 45.0), (0.35, 7.0)]),
)
def test_sampled_routes_step_exactly_and_end_at_the_last_waypoint(
    points: list[tuple[float, float]], spacing: tuple[float, float]
) -> None:
    route = Route(tuple(points))
    poses = sample(route, Sampling(*spacing))
    steps = se2.relative_steps(poses)
    dist = np.hypot(steps[:, 0], steps[:, 1])
    turn = np.abs(steps[:, 2])
    assert np.all((dist < 1e-9) | (turn < 1e-9))  # a step either drives or turns
    assert np.all(dist <= spacing[0] + 1e-9)
    assert np.all(turn <= math.radians(spacing[1]) + 1e-9)
    assert np.all(steps[dist > 1e-9, 0] > 0)  # always forward
    np.testing.assert_allclose(poses[-1, :2], points[-1], atol=1e-9)
    assert se2.path_length(poses) == pytest.approx(route.length, rel=1e-9, abs=1e-9)
