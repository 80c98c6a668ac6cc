"""Albot1+'s consistent information (``consistent_information``): a fit weighs what its own cost says it knows."""

from __future__ import annotations

import math

import numpy as np
import pytest
from plus_room import NO_KINDS, SINCE, localiser, scan_from

from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.consistency import information_scale, stated_distance
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import PlusLocaliser
from albot1.methods.albot1.mapping.start_poses import start_poses

TRUE = (0.02, 0.5, math.radians(2.0))  # the view's true pose: 2 cm aside and turned 2 deg


def test_the_stated_distance_is_the_fits_squared_mahalanobis_distance_with_the_heading_wrapped() -> None:
    info = np.diag([4.0, 9.0, 100.0])
    assert stated_distance(info, (0.5, -1.0 / 3.0, 0.1), (0.0, 0.0, 0.0)) == pytest.approx(3.0, abs=1e-12)
    # across the wrap: pi - 0.05 against -pi + 0.05 is 0.1 rad apart, not 2 pi - 0.1
    assert stated_distance(info, (0.0, 0.0, math.pi - 0.05), (0.0, 0.0, -math.pi + 0.05)) == pytest.approx(1.0)
    coupled = np.array([[2.0, 1.0, 0.5], [1.0, 3.0, 0.0], [0.5, 0.0, 4.0]])
    d = np.array([0.3, -0.2, 0.1])
    assert stated_distance(coupled, tuple(d), (0.0, 0.0, 0.0)) == pytest.approx(float(d @ coupled @ d), abs=1e-15)


def test_the_scale_makes_the_stated_distance_at_most_factor_times_the_likelihood_ratio() -> None:
    assert information_scale(3.0, 12.0) == 0.25
    assert information_scale(3.0, 12.0, 2.0) == 0.5
    assert information_scale(3.0, 12.0, 4.0) == 1.0  # consistent: nothing to scale
    assert information_scale(30.0, 12.0) == 1.0  # the view refutes more strongly than its information says
    assert information_scale(3.0, 12.0, 0.0) == 1.0  # off
    assert information_scale(3.0, 0.0) == 1.0 and information_scale(3.0, math.inf) == 1.0  # nothing measured
    assert information_scale(0.0, 12.0) == 0.0  # the ambiguity test keeps such a view before the fusion anyway


def view_pose(loc: PlusLocaliser, jitter: float) -> tuple[float, float, float]:
    empty = np.empty((0, 4))
    return loc.pose(start_poses(SINCE, None, None), empty, empty, NO_KINDS, scan_from(TRUE, jitter), SINCE, None, True)


def test_a_fit_whose_cost_backs_its_information_is_fused_as_before() -> None:
    """Exact data: the residual variance is zero, the likelihood ratio unbounded, so the scale is 1 (same bits)."""
    off = view_pose(localiser(), 0.0)
    assert abs(off[2] - TRUE[2]) < math.radians(0.1)  # the fit (2 deg) wins over the prediction (0 deg)
    assert view_pose(localiser(consistent_information=1.0), 0.0) == off


def test_an_overstated_fit_is_weighed_by_its_likelihood_ratio(monkeypatch: pytest.MonkeyPatch) -> None:
    """Scattered points (+-3 cm): the fit states more than its cost backs; the fusion scales its information
    down by ``factor * statistic / stated distance`` and moves the pose towards the prediction by exactly that."""
    seen: list[tuple[object, ...]] = []
    loc = localiser(consistent_information=1.0)
    fuse = loc._fuse

    def spy(*args: object) -> tuple[float, float, float]:
        seen.append(args)
        return fuse(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(loc, "_fuse", spy)
    on = view_pose(loc, 0.03)
    off = view_pose(localiser(), 0.03)
    measured, info, predicted, motion, scale, _ = seen[0]
    assert loc.last_ambiguity is not None and not loc.last_ambiguity.ambiguous
    stated = stated_distance(info, measured, predicted)  # type: ignore[arg-type]
    assert 0.0 < float(scale) < 1.0  # type: ignore[arg-type]
    assert scale == loc.last_ambiguity.statistic / stated
    # the combination by information, written out with numpy, with the fit's information scaled
    v_xy, v_phi = loc.noise.prior_variance(float(motion))  # type: ignore[arg-type]
    prior = np.diag([1.0 / v_xy, 1.0 / v_xy, 1.0 / v_phi])
    fit = float(scale) * np.asarray(info)  # type: ignore[arg-type]
    expected = np.linalg.solve(fit + prior, fit @ np.asarray(measured) + prior @ np.asarray(predicted))
    np.testing.assert_allclose(on, expected, rtol=0.0, atol=1e-12)
    # towards the prediction: the heading moves less than the fit's
    assert abs(on[2] - SINCE[2]) < abs(off[2] - SINCE[2])


def test_every_preset_leaves_it_off() -> None:
    for name in ("default", "thesis", "exact", "literal", "plus"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.consistent_information == 0.0
