"""The ray-cast laser: exact ranges in known rooms, doorway gaps, max range, noise and seeding."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.synthetic.errors import SyntheticWorldError
from albot1.data.synthetic.floorplan import DoorwaySpec, Space, build_plan
from albot1.data.synthetic.lidar import LaserSpec, add_noise, cast, cast_many

SICK = LaserSpec(range_sigma=0.0)


def square(half: float) -> np.ndarray:
    """The four walls of a square room of side ``2 * half`` centred on the origin."""
    h = half
    return np.array([[-h, -h, h, -h], [h, -h, h, h], [h, h, -h, h], [-h, h, -h, -h]])


def square_ranges(half: float, bearings: np.ndarray) -> np.ndarray:
    """Distance from the centre of the square to its wall along world bearings."""
    return half / np.maximum(np.abs(np.cos(bearings)), np.abs(np.sin(bearings)))


def test_sick_lms200_beam_layout() -> None:
    angles = SICK.angles
    assert angles.shape == (181,)
    assert angles[0] == pytest.approx(-math.pi / 2, abs=1e-15)
    assert angles[90] == pytest.approx(0.0, abs=1e-15)
    assert angles[-1] == pytest.approx(math.pi / 2, abs=1e-15)
    np.testing.assert_allclose(np.diff(angles), math.radians(1.0), atol=1e-15)
    assert SICK.resolution_deg == pytest.approx(1.0)


@pytest.mark.parametrize("heading_deg", [0.0, 90.0, -90.0, 180.0, 30.0, -137.0])
def test_centre_of_a_square_room_gives_the_known_ranges(heading_deg: float) -> None:
    heading = math.radians(heading_deg)
    got = cast(square(2.0), [0.0, 0.0, heading], SICK.angles, 30.0)
    np.testing.assert_allclose(got, square_ranges(2.0, SICK.angles + heading), rtol=0, atol=1e-12)


def test_known_ranges_at_round_angles() -> None:
    got = cast(square(2.0), [0.0, 0.0, 0.0], SICK.angles, 30.0)
    assert got[90] == pytest.approx(2.0, abs=1e-12)  # straight ahead
    assert got[0] == pytest.approx(2.0, abs=1e-12)  # right, beam 0 at -90 deg
    assert got[180] == pytest.approx(2.0, abs=1e-12)  # left
    assert got[135] == pytest.approx(2.0 * math.sqrt(2.0), abs=1e-12)  # exactly into the corner
    assert got[45] == pytest.approx(2.0 * math.sqrt(2.0), abs=1e-12)
    assert got[120] == pytest.approx(2.0 / math.cos(math.radians(30.0)), abs=1e-12)


def test_the_room_seen_from_a_translated_and_rotated_pose() -> None:
    offset, heading = np.array([5.0, -3.0]), math.radians(20.0)
    walls = square(2.0) + np.tile(offset, 2)
    got = cast(walls, [offset[0], offset[1], heading], SICK.angles, 30.0)
    np.testing.assert_allclose(got, square_ranges(2.0, SICK.angles + heading), atol=1e-12)


def test_a_full_circle_scanner_sees_behind_itself() -> None:
    laser = LaserSpec(beams=361, fov_deg=360.0, range_sigma=0.0)
    for heading in (0.0, 0.7, math.pi):
        got = cast(square(1.5), [0.0, 0.0, heading], laser.angles, 30.0)
        np.testing.assert_allclose(got, square_ranges(1.5, laser.angles + heading), atol=1e-12)


@pytest.mark.parametrize("first_deg", [0.0, -360.0, 90.0])
def test_beams_given_beyond_plus_minus_180_deg_hit_the_walls_there(first_deg: float) -> None:
    # A TurtleBot's LDS-01 lists its 360 beams from 0 to 359 deg: the beams past 180 deg (behind and to the
    # right) used to hit nothing and read NaN. Each beam must read the square's wall along its own direction.
    angles = np.radians(first_deg + np.arange(360.0))
    for heading in (0.0, 0.7, -2.5):
        got = cast(square(1.5), [0.0, 0.0, heading], angles, 30.0)
        np.testing.assert_allclose(got, square_ranges(1.5, angles + heading), rtol=0, atol=1e-12)


def test_off_centre_pose_against_a_hand_computed_scan() -> None:
    got = cast(square(2.0), [1.0, 0.5, 0.0], SICK.angles, 30.0)
    assert got[90] == pytest.approx(1.0)  # forward to x = 2
    assert got[0] == pytest.approx(2.5)  # right to y = -2
    assert got[180] == pytest.approx(1.5)  # left to y = 2
    # 45 deg left: the ray reaches x = 2 (after 1 m) at y = 1.5, inside the wall.
    assert got[135] == pytest.approx(math.sqrt(2.0))


def test_a_doorway_gap_is_a_range_discontinuity() -> None:
    # A 4 x 4 room, a 0.2 m wall at x = 4..4.2 with a 1 m doorway centred on y = 0, and a hall behind it.
    plan = build_plan(
        "door",
        [Space("room", (0.0, -2.0, 4.0, 2.0)), Space("hall", (4.2, -2.0, 10.0, 2.0))],
        [DoorwaySpec("d", (4.1, 0.0), "y", 1.0)],
    )
    got = cast(plan.walls, [2.0, 0.0, 0.0], SICK.angles, 30.0)
    deg = {int(a): r for a, r in zip(np.round(np.degrees(SICK.angles)), got, strict=True)}
    # |tan a| < 0.5 / 2.2: through both wall faces, to the hall's far wall at x = 10.
    for a in range(-12, 13):
        assert deg[a] == pytest.approx(8.0 / math.cos(math.radians(a)), abs=1e-12)
    # Between the faces: the jamb (doorway side wall at y = +-0.5).
    for a in (13, 14, -13, -14):
        assert deg[a] == pytest.approx(0.5 / math.sin(math.radians(abs(a))), abs=1e-12)
    # Beyond: the room's own wall at x = 4.
    for a in (15, 30, -15, -30):
        assert deg[a] == pytest.approx(2.0 / math.cos(math.radians(a)), abs=1e-12)
    jumps = np.abs(np.diff(got))
    assert {int(i) for i in np.flatnonzero(jumps > 5.0)} == {90 - 13, 90 + 12}


def test_beyond_max_range_reads_nan() -> None:
    corridor = np.array(
        [[0.0, -1.0, 60.0, -1.0], [60.0, -1.0, 60.0, 1.0], [60.0, 1.0, 0.0, 1.0], [0.0, 1.0, 0.0, -1.0]]
    )
    near = cast(corridor, [2.0, 0.0, 0.0], SICK.angles, 30.0)
    assert np.isnan(near[90])  # the end wall is 58 m away
    assert np.isnan(near[89]) and np.isnan(near[91])  # side walls 57 m away at 1 deg
    assert near[92] == pytest.approx(1.0 / math.sin(math.radians(2.0)))  # 28.65 m: within range
    finite = np.isfinite(near)
    assert np.all(near[finite] <= 30.0)
    far = cast(corridor, [2.0, 0.0, 0.0], SICK.angles, 100.0)
    assert far[90] == pytest.approx(58.0)
    assert np.all(np.isfinite(far))


def test_no_walls_means_no_returns() -> None:
    assert np.all(np.isnan(cast(np.empty((0, 4)), [0.0, 0.0, 0.0], SICK.angles, 30.0)))


def test_walls_are_two_sided_and_the_nearest_wins() -> None:
    walls = np.array([[3.0, -5.0, 3.0, 5.0], [1.0, 1.0, 1.0, -1.0], [2.0, -5.0, 2.0, 5.0]])
    got = cast(walls, [0.0, 0.0, 0.0], SICK.angles, 30.0)
    assert got[90] == pytest.approx(1.0)
    assert got[90 + 60] == pytest.approx(2.0 / math.cos(math.radians(60.0)))


def test_cast_many_matches_cast() -> None:
    walls = square(3.0)
    rng = np.random.default_rng(5)
    poses = np.column_stack([rng.uniform(-2.5, 2.5, 50), rng.uniform(-2.5, 2.5, 50), rng.uniform(-4, 4, 50)])
    many = cast_many(walls, poses, SICK.angles, 30.0, batch=7)
    for pose, row in zip(poses, many, strict=True):
        np.testing.assert_array_equal(row, cast(walls, pose, SICK.angles, 30.0))


def test_noise_is_seeded_zero_mean_with_the_given_sigma() -> None:
    exact = np.full(20000, 5.0)
    a = add_noise(exact, 0.01, 30.0, np.random.default_rng(1))
    np.testing.assert_array_equal(a, add_noise(exact, 0.01, 30.0, np.random.default_rng(1)))
    assert not np.array_equal(a, add_noise(exact, 0.01, 30.0, np.random.default_rng(2)))
    assert abs(float(np.mean(a - 5.0))) < 4 * 0.01 / math.sqrt(len(a))
    assert float(np.std(a - 5.0)) == pytest.approx(0.01, rel=0.03)


def test_noise_keeps_nan_turns_overshoot_into_nan_and_clips_at_zero() -> None:
    exact = np.array([np.nan, 29.99, 0.001, 10.0])
    got = add_noise(exact, 1.0, 30.0, np.random.default_rng(3))
    assert np.isnan(got[0])
    noisy = np.array([29.99, 0.001]) + np.random.default_rng(3).normal(0.0, 1.0, 4)[1:3]
    assert np.isnan(got[1]) == (noisy[0] > 30.0)
    assert got[2] == max(noisy[1], 0.0)
    np.testing.assert_array_equal(add_noise(exact, 0.0, 30.0, np.random.default_rng(0)), exact)


def test_input_validation() -> None:
    with pytest.raises(SyntheticWorldError, match="shape"):
        cast(np.zeros((3, 3)), [0, 0, 0], SICK.angles, 30.0)
    with pytest.raises(SyntheticWorldError, match="ascending"):
        cast(square(1.0), [0, 0, 0], SICK.angles[::-1], 30.0)
    with pytest.raises(SyntheticWorldError, match="beams"):
        LaserSpec(beams=1)
    with pytest.raises(SyntheticWorldError, match="field of view"):
        LaserSpec(fov_deg=0.0)
    with pytest.raises(SyntheticWorldError, match="max range"):
        LaserSpec(max_range=math.inf)
    with pytest.raises(SyntheticWorldError, match="sigma"):
        LaserSpec(range_sigma=-0.1)
