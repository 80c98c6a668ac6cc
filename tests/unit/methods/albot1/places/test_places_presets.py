"""albot1-places presets: every chapter-3 preset with the places fields on top; registry and env prefix."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.config.presets import preset_file
from albot1.errors import ConfigError
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.places.config import Albot1PlacesConfig, PlacesFields
from albot1.methods.albot1.places.mapper import Albot1PlacesMapper
from albot1.methods.registry import get_method, resolve_method_config


def test_every_chapter3_preset_is_a_places_preset_with_the_same_chapter3_values() -> None:
    chapter3, places = Albot1Mapper.presets, Albot1PlacesMapper.presets
    assert set(chapter3) <= set(places)
    for name, values in chapter3.items():
        assert {k: places[name][k] for k in Albot1Config.model_fields} == values, name
        assert set(places[name]) == set(Albot1PlacesConfig.model_fields)


def test_places_values_come_from_the_places_file() -> None:
    presets = Albot1PlacesMapper.presets
    assert presets["thesis"]["match_min_matches"] == 5 and presets["thesis"]["place_surface_min_m"] == 0.4
    assert presets["thesis"]["revisit_evidence"] == "memory"
    assert presets["literal"]["revisit_evidence"] == "perceptual_map"
    # the places file's default equals the model's defaults (the model can be built in code)
    defaults = {k: f.default for k, f in PlacesFields.model_fields.items()}
    assert {k: presets["default"][k] for k in PlacesFields.model_fields} == defaults


def test_the_config_is_the_chapter3_config_plus_places_fields() -> None:
    cfg = Albot1PlacesConfig()
    assert isinstance(cfg, Albot1Config) and cfg.motion_model == "thesis" and cfg.exit_max_width_m == 1.2
    with pytest.raises(ValueError, match="extra"):
        Albot1PlacesConfig(no_such_field=1)


def test_registry_environment_and_overrides(monkeypatch: pytest.MonkeyPatch) -> None:
    spec = get_method("albot1-places")
    assert spec.env_prefix == "ALBOT1_ALBOT1_PLACES_"
    monkeypatch.setenv("ALBOT1_ALBOT1_PLACES_EXIT_MAX_WIDTH_M", "1.1")
    monkeypatch.setenv("ALBOT1_ALBOT1_CORNER_MIN_ANGLE_DEG", "45")  # chapter 3's variable: not this method's
    resolved = resolve_method_config("albot1-places", "exact", {"match_min_matches": "6"})
    cfg = resolved.config
    assert (cfg.motion_model, cfg.exit_max_width_m, cfg.match_min_matches) == ("exact", 1.1, 6)
    assert cfg.corner_min_angle_deg == 30.0


def test_a_bad_places_value_names_the_files_and_the_preset(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """A user's override of the places file (ALBOT1_CONFIG_DIR) is read the same way and its errors name both files."""
    (tmp_path / "baselines").mkdir()
    text = preset_file("albot1-places").read_text(encoding="utf-8")
    (tmp_path / "baselines" / "albot1-places.toml").write_text(text + "\n[presets.exact]\nexit_min_width_m = 2.0\n")
    monkeypatch.setenv("ALBOT1_CONFIG_DIR", str(tmp_path))

    class Fresh(Albot1PlacesMapper):  # a new owner class: the descriptor reads the files again
        pass

    with pytest.raises(
        ConfigError,
        match=r"albot1.toml \+ .*albot1-places.toml: preset 'exact' is not a valid Albot1PlacesConfig.*exit_min",
    ):
        _ = Fresh.presets
    assert Albot1PlacesMapper.__dict__["presets"].location(Fresh) == str(tmp_path / "baselines" / "albot1-places.toml")
