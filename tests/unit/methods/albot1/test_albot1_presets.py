"""Albot1's presets, read from baselines/albot1.toml, are exactly the documented values.

The expected values below were a literal copy of what the presets resolved to
when they were a dict in the mapping config module (every field of the model
at its default, plus each preset's changes), so the move to a TOML file could
not change a single number, type or string. Since then, deliberately
(``docs/albot1-mapper.md``): the beam-spacing test (``end_spacing_max_m``
0.2, off in ``literal``), the line-fit and Albot1+ fields (off outside
``plus``), the ``plus`` preset, and the grid cell field removed with the grid.
"""

from __future__ import annotations

import os
from typing import Any

import pytest

from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.registry import resolve_config

#: Albot1Config() before the move, field by field.
OLD_DEFAULT: dict[str, Any] = {
    "max_range_m": 30.0,
    "cluster_gap_m": 0.6,
    "cluster_size_m": 0.2,
    "break_point_height_m": 0.1,
    "surface_length_m": 0.1,
    "landmark_min_length_m": 0.4,
    "corner_min_angle_deg": 30.0,
    "occlusion_margin_m": 0.0,
    "continuation_tolerance_m": 0.1,
    "end_spacing_max_m": 0.2,
    "end_spacing_grazing": 0.0,
    "surface_fit": "chord",
    "motion_model": "thesis",
    "recognition_angle_deg": 5.0,
    "recognition_distance_m": 0.4,
    "recognition_matching": "greedy",
    "min_landmarks": 3,
    "pose_between_updates": "localise",
    "outlier_min_candidates": 3,
    "goodness_gap_floor_m": 0.01,
    "goodness_angle_floor_deg": 0.1,
    "goodness_distance_view": "previous",
    "pose_estimate": "landmark",
    "robust_line_sigma_m": 0.05,
    "robust_point_sigma_m": 0.1,
    "robust_huber_sigmas": 2.0,
    "robust_iterations": 8,
    "scan_refinement": False,
    "scan_sigma_m": 0.05,
    "scan_gate_m": 0.5,
    "scan_beam_stride": 2,
    "scan_overlap": "gate",
    "scan_overhang_m": 0.0,
    "odometry_prior": "off",
    "prior_xy_m_per_sqrt_m": 0.05,
    "prior_deg_per_sqrt_m": 2.0,
    "prior_m_per_rad": 1.0,
    "prior_learning_rate": 0.02,
    "degenerate_sd_m": 0.0,
    "gate_probability": 0.0,
    "ambiguity_probability": 0.0,
    "window_updates": 0,
    "window_probability": 0.5,
    "turn_bound_floor_deg": 0.0,
    "turn_bound_scale": 1.0,
    "turn_bound_statistic": 0.0,
    "consistent_information": 0.0,
    "view_noise_learning_rate": 0.0,
    "fit_noise_factor": 0.0,
    "fit_noise_statistic": 0.0,
    "fit_noise_source": "kept",
    "mount_prior_m": 0.0,
    "kept_views_teach": False,
    "refutation_probability": 0.0,
    "noise_split_samples": 0,
    "update_polygon": "robot_and_endpoints",
    "delete_margin_m": 0.4,
    "delete_margin_from": "surfaces",
    "correspond_angle_deg": 5.0,
    "correspond_distance_m": 0.4,
    "partial_without_match": "clip",
    "odometry_jump_m": 5.0,
    "stationary_m": 1e-06,
    "stationary_deg": 1e-06,
    "accelerate": True,
}

#: The old ``PRESETS`` dict: each preset's changes relative to the model defaults.
OLD_PRESETS: dict[str, dict[str, Any]] = {
    "default": {},
    "thesis": {},
    "exact": {"motion_model": "exact"},
    "literal": {"delete_margin_from": "boundary", "continuation_tolerance_m": 0.0, "end_spacing_max_m": 0.0},
    "plus": {
        "motion_model": "exact",
        "surface_fit": "tls",
        "end_spacing_max_m": 0.0,
        "pose_estimate": "robust",
        "scan_refinement": True,
        "odometry_prior": "adaptive",
        "degenerate_sd_m": 0.05,
        "gate_probability": 0.0,
        "ambiguity_probability": 0.99,
        "scan_overlap": "surface",
        "scan_overhang_m": 0.05,
        "turn_bound_floor_deg": 3.0,
        "turn_bound_statistic": 40.0,
        "view_noise_learning_rate": 0.05,
        "kept_views_teach": True,
    },
}


def _typed(values: dict[str, Any]) -> dict[str, tuple[type, Any]]:
    """Values with their types, so 3 and 3.0 (or True and 1) do not compare equal."""
    return {name: (type(value), value) for name, value in values.items()}


def test_the_model_defaults_are_unchanged() -> None:
    assert _typed(Albot1Config().model_dump()) == _typed(OLD_DEFAULT)


def test_the_same_preset_names() -> None:
    assert list(Albot1Mapper.presets) == list(OLD_PRESETS)


@pytest.mark.parametrize("name", list(OLD_PRESETS))
def test_each_preset_resolves_to_the_old_values(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    for variable in [v for v in os.environ if v.upper().startswith("ALBOT1_ALBOT1_")]:
        monkeypatch.delenv(variable)
    expected = {**OLD_DEFAULT, **OLD_PRESETS[name]}
    assert _typed(Albot1Config.model_validate(Albot1Mapper.presets[name]).model_dump()) == _typed(expected)
    assert _typed(resolve_config("albot1", name).model_dump()) == _typed(expected)


@pytest.mark.parametrize("name", list(OLD_PRESETS))
def test_each_preset_table_is_complete(name: str) -> None:
    """The TOML mechanism merges ``default`` into every preset: each table sets every field."""
    assert _typed(Albot1Mapper.presets[name]) == _typed({**OLD_DEFAULT, **OLD_PRESETS[name]})
