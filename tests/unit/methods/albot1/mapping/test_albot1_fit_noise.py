"""Albot1+'s fit noise (``fit_noise_factor``, ``fit_noise_statistic``): the views' scatter in a fit's covariance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from plus_room import NO_KINDS, SINCE, localiser, scan_from

from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.fit_noise import fit_noise_factor, with_fit_noise
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import PlusLocaliser
from albot1.methods.albot1.mapping.start_poses import start_poses

TRUE = (0.02, 0.5, math.radians(2.0))  # the view's true pose: 2 cm aside and turned 2 deg


def as_matrix(info: tuple[float, ...]) -> np.ndarray:
    h00, h01, h02, h11, h12, h22 = info
    return np.array([[h00, h01, h02], [h01, h11, h12], [h02, h12, h22]])


def test_a_diagonal_information_gets_the_scatter_added_to_each_variance() -> None:
    # variances 1/400 m^2 and 1/1e4 rad^2, plus 3 x (1e-3 m^2, 2e-4 rad^2)
    got = with_fit_noise((400.0, 0.0, 0.0, 400.0, 0.0, 1e4), (1e-3, 2e-4), 3.0)
    expected = (1.0 / (1.0 / 400.0 + 3e-3), 0.0, 0.0, 1.0 / (1.0 / 400.0 + 3e-3), 0.0, 1.0 / (1e-4 + 6e-4))
    assert got == pytest.approx(expected, rel=1e-14, abs=1e-14)


def test_a_coupled_information_is_that_of_the_summed_covariance_and_stays_symmetric() -> None:
    info = np.array([[900.0, 120.0, -300.0], [120.0, 400.0, 80.0], [-300.0, 80.0, 5e4]])
    got = with_fit_noise((900.0, 120.0, -300.0, 400.0, 80.0, 5e4), [4e-4, 1e-5], 2.0)
    expected = np.linalg.inv(np.linalg.inv(info) + np.diag([8e-4, 8e-4, 2e-5]))
    np.testing.assert_allclose(as_matrix(got), expected, rtol=1e-12)


def test_a_direction_without_information_stays_without_and_factor_zero_changes_nothing() -> None:
    got = with_fit_noise((1e4, 0.0, 0.0, 0.0, 0.0, 1e5), (1e-4, 1e-5), 1.0)  # no information along y
    assert got == pytest.approx((5000.0, 0.0, 0.0, 0.0, 0.0, 50000.0), rel=1e-12)
    info = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)
    assert with_fit_noise(info, (1.0, 1.0), 0.0) is info


def test_the_factor_falls_with_the_square_of_the_likelihood_ratio_beyond_the_scale() -> None:
    assert fit_noise_factor(10.0, 12.0, 40.0) == 10.0  # a weak refutation: all of it
    assert fit_noise_factor(10.0, 40.0, 40.0) == 10.0
    assert fit_noise_factor(10.0, 400.0, 40.0) == pytest.approx(0.1, rel=1e-15)  # ten times the scale: 1 %
    assert fit_noise_factor(10.0, 400.0, 0.0) == 10.0  # no fall-off


def view_pose(loc: PlusLocaliser) -> tuple[float, float, float]:
    empty = np.empty((0, 4))
    return loc.pose(start_poses(SINCE, None, None), empty, empty, NO_KINDS, scan_from(TRUE, 0.03), SINCE, None, True)


def test_a_fused_view_is_combined_with_its_scatter_added(monkeypatch: pytest.MonkeyPatch) -> None:
    """Scattered points (+-3 cm) 2 deg off the prediction: the fusion adds the learnt scatter, times the factor
    (the ratio is below the scale), to the fit's covariance, and the pose is that combination, nearer the
    prediction than without it."""
    seen: list[tuple[object, ...]] = []
    loc = localiser(view_noise_learning_rate=0.05, fit_noise_factor=10.0, fit_noise_statistic=1e9)
    assert loc.view_noise is not None
    fuse = loc._fuse

    def spy(*args: object) -> tuple[float, float, float]:
        seen.append(args)
        return fuse(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(loc, "_fuse", spy)
    on = view_pose(loc)
    off = view_pose(localiser(view_noise_learning_rate=0.05))
    measured, info, predicted, motion, _, statistic = seen[0]
    assert loc.last_ambiguity is not None and statistic == loc.last_ambiguity.statistic
    v_xy, v_phi = loc.noise.prior_variance(float(motion))  # type: ignore[arg-type]
    prior = np.diag([1.0 / v_xy, 1.0 / v_xy, 1.0 / v_phi])
    vn = loc.view_noise.variance
    fit = np.linalg.inv(np.linalg.inv(np.asarray(info)) + 10.0 * np.diag([vn[0], vn[0], vn[1]]))
    expected = np.linalg.solve(fit + prior, fit @ np.asarray(measured) + prior @ np.asarray(predicted))
    np.testing.assert_allclose(on, expected, rtol=0.0, atol=1e-9)
    assert abs(on[2] - SINCE[2]) < abs(off[2] - SINCE[2])


def test_the_thesis_presets_leave_it_off() -> None:
    for name in ("default", "thesis", "exact", "literal"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.fit_noise_factor == 0.0
