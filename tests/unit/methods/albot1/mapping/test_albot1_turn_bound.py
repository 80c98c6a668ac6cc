"""Albot1+'s turn bound (``turn_bound_*``): a view no landmark places turns the robot only on strong evidence."""

from __future__ import annotations

import math

import numpy as np
import pytest
from plus_room import NO_KINDS, SINCE, localiser, scan_from

from albot1.geometry import se2
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import PlusLocaliser
from albot1.methods.albot1.mapping.start_poses import ODOMETRY_TURNS_DEG, start_poses
from albot1.methods.albot1.mapping.turn_bound import allowance, beyond, bounded_starts


def test_the_allowance_grows_with_the_odometrys_own_turn_and_is_infinite_when_off() -> None:
    assert allowance(math.radians(3.0), 1.0, math.radians(-4.0)) == pytest.approx(math.radians(7.0), abs=1e-15)
    assert allowance(math.radians(3.0), 0.5, math.radians(10.0)) == pytest.approx(math.radians(8.0), abs=1e-15)
    assert allowance(0.0, 1.0, math.radians(90.0)) == math.inf
    assert beyond(math.radians(3.5), math.radians(3.0)) and not beyond(math.radians(-2.9), math.radians(3.0))
    assert not beyond(2.0 * math.pi + 0.01, 0.02)  # headings are compared wrapped


def test_only_the_starts_within_the_allowance_of_the_odometrys_are_kept() -> None:
    starts = start_poses((1.0, 2.0, math.pi - 0.01), None, None)  # near the wrap: offsets still measured wrapped
    near = bounded_starts(starts, math.radians(6.0))
    kept = np.degrees(np.asarray([se2.wrap_angle(h - starts[0, 2]) for h in near[:, 2]]))
    np.testing.assert_allclose(kept, [0.0, -3.0, 3.0, -6.0, 6.0], atol=1e-9)
    assert near.flags.c_contiguous and (near[:, :2] == (1.0, 2.0)).all()
    assert bounded_starts(starts, 0.0).shape == (1, 3)  # the unturned start always
    assert bounded_starts(starts, math.inf).shape == (len(ODOMETRY_TURNS_DEG), 3)


TURNED = (0.0, 0.5, math.radians(10.0))  # the view's true pose: also turned 10 deg


def view_pose(loc: PlusLocaliser, *, placed: bool) -> tuple[float, float, float]:
    since = SINCE
    starts = start_poses(since, None, None)
    empty = np.empty((0, 4))
    return loc.pose(starts, empty, empty, NO_KINDS, scan_from(TURNED), since, None, placed)


def turns(pose: tuple[float, float, float]) -> bool:
    """The pose is the fit's (exact data: 10 deg), fused with the prediction by the learnt spread's start values."""
    return abs(pose[2] - TURNED[2]) < math.radians(0.2) and math.hypot(pose[0], pose[1] - 0.5) < 0.01


def test_off_the_view_turns_freely() -> None:
    loc = localiser()
    assert turns(view_pose(loc, placed=False))
    assert loc.turn_bounded_views == 0


def test_a_turn_the_odometry_did_not_make_is_refitted_from_the_near_starts_when_weakly_supported() -> None:
    """The statistic (exact data: far above any limit) is declared weak: the fit from the starts within 3 deg
    still ends at the true 10 deg, beyond the allowance, so the prediction is the pose."""
    loc = localiser(turn_bound_floor_deg=3.0, turn_bound_scale=1.0, turn_bound_statistic=1e300)
    assert view_pose(loc, placed=False) == SINCE  # the prediction: the update view at the origin, plus SINCE
    assert loc.turn_bounded_views == 1


def test_a_strong_refutation_of_the_odometry_turns_the_robot() -> None:
    loc = localiser(turn_bound_floor_deg=3.0, turn_bound_scale=1.0, turn_bound_statistic=1e6)
    assert turns(view_pose(loc, placed=False))
    assert loc.turn_bounded_views == 0


def test_views_a_landmark_places_and_turns_within_the_allowance_are_left_alone() -> None:
    loc = localiser(turn_bound_floor_deg=3.0, turn_bound_scale=1.0, turn_bound_statistic=1e300)
    assert turns(view_pose(loc, placed=True))
    loc = localiser(turn_bound_floor_deg=11.0, turn_bound_scale=1.0, turn_bound_statistic=1e300)
    assert turns(view_pose(loc, placed=False))
    assert loc.turn_bounded_views == 0


def test_the_thesis_presets_leave_the_bound_off() -> None:
    for name in ("default", "thesis", "exact", "literal"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.turn_bound_floor_deg == 0.0


def test_the_refit_starts_centre_on_the_prediction_not_on_the_first_start(monkeypatch: pytest.MonkeyPatch) -> None:
    """Between updates the first start (the previous view's pose and the step) is not the prediction the
    allowance is measured from (the update view's pose and the odometry since): the refit starts around the latter."""
    loc = localiser(turn_bound_floor_deg=3.0, turn_bound_scale=1.0, turn_bound_statistic=1e300)
    seen: list[np.ndarray] = []
    solve = loc._solve

    def spy(starts: np.ndarray, *rest: object) -> object:
        seen.append(np.array(starts))
        return solve(starts, *rest)  # type: ignore[arg-type]

    monkeypatch.setattr(loc, "_solve", spy)
    first = (0.0, 0.5, math.radians(8.0))  # a previous view refined 8 deg away from the prediction
    empty = np.empty((0, 4))
    pose = loc.pose(start_poses(first, None, None), empty, empty, NO_KINDS, scan_from(TURNED), SINCE, None, False)
    assert pose == SINCE and loc.turn_bounded_views == 1  # the true 10 deg is beyond 3 deg from the prediction
    assert len(seen) == 2
    np.testing.assert_allclose(np.degrees(seen[1][:, 2]), [0.0, -3.0, 3.0], atol=1e-9)
    assert (seen[1][:, :2] == SINCE[:2]).all()
