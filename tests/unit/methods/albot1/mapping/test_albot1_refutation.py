"""Albot1+'s refutation test (``refutation_probability``): a departure the view noise explains keeps the odometry."""

from __future__ import annotations

import math

import numpy as np
import pytest
from plus_room import NO_KINDS, SINCE, localiser, scan_from
from pydantic import ValidationError

from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import PlusLocaliser
from albot1.methods.albot1.mapping.refutation import refutation_statistic, refutes
from albot1.methods.albot1.mapping.start_poses import start_poses


def test_the_statistic_is_the_departure_in_units_of_the_fit_and_view_variances() -> None:
    # diagonal information 1/0.01^2 per axis and 1/0.001^2 in heading, view noise 0.02^2 and 0.002^2
    info = (1e4, 0.0, 0.0, 1e4, 0.0, 1e6)
    variance = (4e-4, 4e-6)
    measured, predicted = (0.05, -0.05, 0.01), (0.0, 0.0, 0.0)
    expected = 2 * 0.05**2 / (1e-4 + 4e-4) + 0.01**2 / (1e-6 + 4e-6)
    assert refutation_statistic(measured, info, predicted, variance) == pytest.approx(expected, rel=1e-12)
    # across the wrap, the heading departure is 0.01 rad, not 2 pi
    wrapped = refutation_statistic((0.05, -0.05, math.pi - 0.005), info, (0.0, 0.0, -math.pi + 0.005), variance)
    assert wrapped == pytest.approx(expected, rel=1e-9)


def test_a_direction_the_fit_leaves_free_refutes_nothing_and_the_others_count_against_both_variances() -> None:
    # no information along x: a 10 m departure there counts for nothing; along y, 0.01^2 + 0.05^2 of variance
    info = (0.0, 0.0, 0.0, 1e4, 0.0, 1e6)
    assert refutation_statistic((10.0, 0.0, 0.0), info, (0.0, 0.0, 0.0), (2.5e-3, 1e-6)) == 0.0
    limit = 0.1**2 / (1e-4 + 2.5e-3)
    rows = [[0.0, 0.0, 0.0], [0.0, 1e4, 0.0], [0.0, 0.0, 1e6]]
    assert not refutes((10.0, 0.0999, 0.0), rows, (0.0, 0.0, 0.0), (2.5e-3, 1e-6), limit)
    assert refutes((0.0, 0.1001, 0.0), rows, (0.0, 0.0, 0.0), (2.5e-3, 1e-6), limit)


def view_pose(loc: PlusLocaliser, true: tuple[float, float, float]) -> tuple[float, float, float]:
    empty = np.empty((0, 4))
    return loc.pose(start_poses(SINCE, None, None), empty, empty, NO_KINDS, scan_from(true), SINCE, None, True)


def test_a_view_the_ambiguity_test_lets_through_keeps_the_prediction_when_its_noise_explains_the_departure() -> None:
    turned = (0.03, 0.5, math.radians(5.0))  # 3 cm aside and 5 deg turned: the ambiguity test lets it through
    off = localiser(view_noise_learning_rate=0.05)
    assert view_pose(off, turned) != SINCE and off.unrefuted_views == 0
    # a view noise of 0.1 m and 0.2 rad explains that departure: the prediction is kept, and it teaches the learner
    on = localiser(view_noise_learning_rate=0.05, refutation_probability=0.99)
    assert on.view_noise is not None
    on.view_noise.variance = [0.01, 0.04]
    samples = on.noise.samples
    assert view_pose(on, turned) == SINCE
    assert on.unrefuted_views == 1 and on.ambiguous_views == 0 and on.noise.samples == samples + 1
    # a view noise of 1 mm and 0.01 rad does not: the view refutes the odometry and is fused as before
    tight = localiser(view_noise_learning_rate=0.05, refutation_probability=0.99)
    assert tight.view_noise is not None
    tight.view_noise.variance = [1e-6, 1e-4]
    reference = localiser(view_noise_learning_rate=0.05)
    assert reference.view_noise is not None
    reference.view_noise.variance = [1e-6, 1e-4]
    assert view_pose(tight, turned) == view_pose(reference, turned) and tight.unrefuted_views == 0


def test_it_is_off_in_every_preset_and_without_the_view_noise() -> None:
    for name in ("default", "thesis", "exact", "literal", "plus"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.refutation_probability == 0.0
    plus = {**Albot1Mapper.presets["default"], **Albot1Mapper.presets["plus"]}
    # without the view noise, or with the noise split replacing it, the setting would do nothing: refused
    for without in ({"view_noise_learning_rate": 0.0}, {"noise_split_samples": 200}):
        with pytest.raises(ValidationError, match="refutation_probability needs the view noise"):
            Albot1Config.model_validate({**plus, "refutation_probability": 0.99, **without})
