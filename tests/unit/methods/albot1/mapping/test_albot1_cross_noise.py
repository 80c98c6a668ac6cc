"""Albot1+'s cross fit noise (``fit_noise_source = "cross"``): the fit's scatter from two fits of one view."""

from __future__ import annotations

import math

import numpy as np
import pytest
from plus_room import NO_KINDS, ROOM, SINCE, localiser, scan_from
from pydantic import ValidationError

from albot1.geometry.segments import transform_segments
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import PlusLocaliser
from albot1.methods.albot1.mapping.start_poses import start_poses
from albot1.methods.albot1.mapping.view_noise import START, ViewNoise

CROSS = {"fit_noise_factor": 1.0, "fit_noise_source": "cross"}


def test_half_the_squared_difference_of_two_fits_is_one_sample_of_a_fits_variance() -> None:
    noise = ViewNoise(0.05)
    # 2 mm apart on one axis: 0.25 * 4e-6 = 1e-6 per axis, above 0.455 times the start; 0.02 rad: 2e-4, above too
    noise.learn_cross((0.002, 0.0, 0.02), (0.0, 0.0, 0.0))
    assert noise.variance == [START[0] * math.exp(0.1), START[1] * math.exp(0.1)]
    noise = ViewNoise(0.05)
    # 1 mm and 5 mrad across the wrap: 2.5e-7 and 1.25e-5, both below 0.455 times the start
    noise.learn_cross((0.0, 0.001, math.pi - 0.0025), (0.0, 0.0, -math.pi + 0.0025))
    assert noise.variance == [START[0] * math.exp(-0.1), START[1] * math.exp(-0.1)]


def view_pose(loc: PlusLocaliser, true: tuple[float, float, float]) -> tuple[float, float, float]:
    empty = np.empty((0, 4))
    return loc.pose(start_poses(SINCE, None, None), empty, empty, NO_KINDS, scan_from(true), SINCE, None, True)


def test_a_view_fitted_against_two_update_views_teaches_their_disagreement_and_not_the_odometrys() -> None:
    loc = localiser(**CROSS)
    assert loc.cross is not None and loc.view_noise is not None
    view_pose(loc, SINCE)  # one update view only: nothing to fit against twice
    assert loc.cross.noise.variance == list(START)
    # the next update view placed 1 cm off in x: the room's surfaces in the map shifted by it
    placed = (0.01, 0.0, 0.0)
    loc.reset(transform_segments(placed, ROOM), placed)
    kept = list(loc.view_noise.variance)
    view_pose(loc, SINCE)  # the view 0.5 m ahead of the new update view, as its odometry says
    # against the new update view it sits at x = 0.01, against the one before at x = 0: 1 cm apart, headings equal
    assert loc.cross.noise.variance == [START[0] * math.exp(0.1), START[1] * math.exp(-0.1)]
    # the kept views' view noise learns as before (the prediction is not refuted: a kept view)
    assert loc.ambiguous_views == 2 and loc.view_noise.variance != kept


def test_the_fusion_adds_the_cross_scatter_where_the_kept_view_noise_would_be() -> None:
    turned = (0.0, 0.5, math.radians(4.0))  # refutes the odometry: fused
    poses = []
    for source, scatter in (("kept", 1e-4), ("cross", 1e-4), ("cross", 1e-8)):
        loc = localiser(fit_noise_factor=1.0, fit_noise_source=source)
        noise = loc.view_noise if source == "kept" else (loc.cross.noise if loc.cross is not None else None)
        assert noise is not None
        noise.variance = [scatter, scatter]
        poses.append(view_pose(loc, turned))
    assert poses[0] == poses[1]
    assert poses[1] != poses[2]  # a smaller scatter: the fit weighs more against the prediction
    assert abs(poses[2][2] - SINCE[2]) > abs(poses[1][2] - SINCE[2])


def test_it_is_off_in_every_preset_and_refused_where_it_would_do_nothing() -> None:
    for name in ("default", "thesis", "exact", "literal", "plus"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.fit_noise_source == "kept" and not config.plus_params().cross_fit_noise
    assert localiser().cross is None
    plus = {**Albot1Mapper.presets["default"], **Albot1Mapper.presets["plus"]}
    for without in ({"fit_noise_factor": 0.0}, {"view_noise_learning_rate": 0.0}, {"noise_split_samples": 200}):
        with pytest.raises(ValidationError, match="fit_noise_source = 'cross' needs the fit noise"):
            Albot1Config.model_validate({**plus, **CROSS, **without})
