"""Albot1+'s view noise (``view_noise_learning_rate``): the views' own scatter out of the odometry learner."""

from __future__ import annotations

import math

import numpy as np
import pytest
from plus_room import NO_KINDS, SINCE, localiser, scan_from

from albot1.geometry import se2
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import PlusLocaliser
from albot1.methods.albot1.mapping.start_poses import start_poses
from albot1.methods.albot1.mapping.view_noise import FLOOR, START, ViewNoise


def test_the_median_tracker_steps_towards_each_sample_by_the_learning_rate() -> None:
    noise = ViewNoise(0.05)
    assert noise.variance == list(START)
    noise.learn((0.0, 0.0, 0.1), (0.0, 0.0, 0.0))  # heading 0.1 rad off: above its median; position exact: below
    assert noise.variance == [START[0] * math.exp(-0.1), START[1] * math.exp(0.1)]
    # across the wrap: pi - 0.005 against -pi + 0.005 is 0.01 rad apart (1e-4 rad^2, above 0.455 times the median)
    noise = ViewNoise(0.05)
    noise.learn((0.003, 0.0, math.pi - 0.005), (0.0, 0.0, -math.pi + 0.005))
    assert noise.variance == [START[0] * math.exp(0.1), START[1] * math.exp(0.1)]


def test_the_views_own_variance_is_taken_out_of_a_teaching_sample_down_to_a_floor() -> None:
    noise = ViewNoise(0.05)
    assert noise.remove(5e-6, 3e-4) == pytest.approx((4e-6, 2e-4), rel=1e-12)
    assert noise.remove(5e-7, 5e-5) == FLOOR


def view_pose(loc: PlusLocaliser, true: tuple[float, float, float]) -> tuple[float, float, float]:
    empty = np.empty((0, 4))
    return loc.pose(start_poses(SINCE, None, None), empty, empty, NO_KINDS, scan_from(true), SINCE, None, True)


def test_kept_views_teach_the_view_noise_and_teaching_views_teach_the_odometry_less_of_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    loc = localiser(view_noise_learning_rate=0.05)
    assert loc.view_noise is not None
    # a view where the odometry is right: not refuted, kept as the prediction, and its (zero) scatter is learnt
    assert view_pose(loc, SINCE) == SINCE and loc.ambiguous_views == 1
    assert loc.view_noise.variance == [START[0] * math.exp(-0.1), START[1] * math.exp(-0.1)]
    taught: list[tuple[float, float, float]] = []
    fused: list[tuple[object, ...]] = []
    learn, fuse = loc.noise.learn, loc._fuse

    def spy_learn(nu2_xy: float, nu2_phi: float, motion: float) -> None:
        taught.append((nu2_xy, nu2_phi, motion))
        learn(nu2_xy, nu2_phi, motion)

    def spy_fuse(*args: object) -> tuple[float, float, float]:
        fused.append(args)
        return fuse(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(loc.noise, "learn", spy_learn)
    monkeypatch.setattr(loc, "_fuse", spy_fuse)
    # a view 3 cm aside and 5 deg turned: it refutes the odometry and teaches it, less the view's own scatter
    view_pose(loc, (0.03, 0.5, math.radians(5.0)))
    measured, _, predicted = fused[0][:3]
    raw_xy = 0.5 * ((measured[0] - predicted[0]) ** 2 + (measured[1] - predicted[1]) ** 2)  # type: ignore[index]
    raw_phi = se2.wrap_angle(measured[2] - predicted[2]) ** 2  # type: ignore[index]
    assert raw_phi > 1e-3  # the fit found the turn
    expected = (raw_xy - START[0] * math.exp(-0.1), raw_phi - START[1] * math.exp(-0.1))
    assert taught == [(pytest.approx(expected[0], rel=1e-12), pytest.approx(expected[1], rel=1e-12), 0.5)]


def test_off_the_learner_sees_the_whole_disagreement_and_the_thesis_presets_leave_it_off() -> None:
    assert localiser(view_noise_learning_rate=0.0).view_noise is None
    for name in ("default", "thesis", "exact", "literal"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.view_noise_learning_rate == 0.0
    plus = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets["plus"]})
    assert plus.view_noise_learning_rate == 0.05
