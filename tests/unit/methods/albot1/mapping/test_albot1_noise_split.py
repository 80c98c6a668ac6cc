"""Albot1+'s noise split (``noise_split_samples``): the odometry's and the views' variance from one line."""

from __future__ import annotations

import pytest
from plus_room import localiser
from pydantic import ValidationError

from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.noise_split import CLIP, MIN_WEIGHT, NoiseSplit, _line
from albot1.methods.albot1.mapping.plus import PRIOR_FLOOR

START_Q = (2.5e-3, 1.2e-3)
START_V = (1e-6, 1e-4)


def test_samples_on_a_line_give_its_intercept_as_the_view_noise_and_its_slope_as_the_odometry_noise() -> None:
    split = NoiseSplit(10**9, START_Q, START_V, PRIOR_FLOOR)  # no forgetting to speak of
    for k in range(40):
        s = 0.1 + 0.05 * k
        split.learn(4e-4 + 1e-4 * s, 2e-5 + 3e-6 * s, s)  # exactly V + q s
    assert split.variance == pytest.approx([4e-4, 2e-5], rel=1e-6)
    assert split.q == pytest.approx([1e-4, 3e-6], rel=1e-6)
    assert split.prior_variance(2.0) == pytest.approx((PRIOR_FLOOR[0] + 2e-4, PRIOR_FLOOR[1] + 6e-6), rel=1e-6)


def test_the_start_values_hold_until_enough_samples_and_a_mismatch_is_clipped() -> None:
    split = NoiseSplit(10**9, START_Q, START_V, PRIOR_FLOOR)
    for _ in range(int(MIN_WEIGHT) - 1):
        split.learn(1.0, 1.0, 1.0)
    assert (split.variance, split.q) == (list(START_V), list(START_Q))
    # a sample far above the line counts as CLIP times the line's value there, not as itself
    fresh = NoiseSplit(10**9, START_Q, START_V, PRIOR_FLOOR)
    fresh.learn(1e3, 1e3, 1.0)
    assert fresh._sums[0][3] == pytest.approx(CLIP * (START_V[0] + START_Q[0]))


def test_a_line_is_held_non_negative() -> None:
    # falling with motion: all of it is the views' (the mean); through below zero: all of it the odometry's
    w, s, ss = 2.0, 3.0, 5.0  # samples at s = 1 and 2
    assert _line([w, s, ss, 3.0, 1.0 * 2.0 + 2.0 * 1.0]) == pytest.approx((1.5, 0.0))  # y = 2 at 1, 1 at 2
    assert _line([w, s, ss, 0.5, 1.0 * 0.0 + 2.0 * 0.5]) == pytest.approx((0.0, 1.0 / 5.0))  # y = 0 at 1, 0.5 at 2
    # every sample at one motion: the odometry's at that motion
    assert _line([2.0, 2.0, 2.0, 0.4, 0.4]) == pytest.approx((0.0, 0.2))


def test_it_replaces_both_learners_when_on_and_is_off_in_every_preset() -> None:
    loc = localiser(noise_split_samples=200)
    assert loc.split is not None and loc.noise is loc.split and loc.view_noise is None
    assert localiser().split is None
    for name in ("default", "thesis", "exact", "literal", "plus"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.noise_split_samples == 0
    plus = {**Albot1Mapper.presets["default"], **Albot1Mapper.presets["plus"]}
    for few in (1, 9):  # fewer views of memory than the split needs to leave its start values: refused
        with pytest.raises(ValidationError, match="noise_split_samples: expected 0 \\(off\\) or at least 10 views"):
            Albot1Config.model_validate({**plus, "noise_split_samples": few})
    assert Albot1Config.model_validate({**plus, "noise_split_samples": 10}).noise_split_samples == 10
