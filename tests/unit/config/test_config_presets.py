"""Presets read from TOML (albot1.config.presets): baselines/<method>.toml for every method, `extends`."""

from __future__ import annotations

import tomllib
from typing import Any, ClassVar

import pytest
from pydantic import BaseModel, ConfigDict, Field

from albot1.config.presets import TomlPresets, load_presets, parse_presets, preset_file, preset_names
from albot1.errors import ConfigError
from albot1.methods.baselines.kiss_icp import KissIcpConfig, KissIcpMapper
from albot1.methods.registry import resolve_config


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    size: float = Field(gt=0)
    count: int = Field(ge=1)


def test_presets_inherit_default_and_are_validated() -> None:
    data = {"presets": {"default": {"size": 1.0, "count": 2}, "big": {"size": 5.0}}}
    assert parse_presets(data, _Model, "x.toml") == {
        "default": {"size": 1.0, "count": 2},
        "big": {"size": 5.0, "count": 2},
    }


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({}, r"x.toml: expected a \[presets.default\] table"),
        ({"presets": {"fast": {"size": 1.0}}}, r"expected a \[presets.default\] table"),
        ({"presets": {"default": {"size": 1.0}}}, r"must set every field of _Model; missing: count"),
        (
            {"presets": {"default": {"size": 1.0, "count": 2}, "bad": {"count": 0}}},
            r"x.toml: preset 'bad' is not a valid _Model: count: Input should be greater than or equal to 1",
        ),
        (
            {"presets": {"default": {"size": 1.0, "count": 2, "colour": "red"}}},
            r"preset 'default' .* colour: Extra inputs",
        ),
        ({"presets": {"default": {"size": 1.0, "count": 2}}, "size": 3}, r"unexpected top-level key\(s\) size"),
        ({"presets": {"default": {"size": 1.0, "count": 2}, "fast": 3}}, r"presets.fast must be a table"),
    ],
)
def test_bad_preset_files_name_file_preset_and_field(data: dict[str, Any], message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        parse_presets(data, _Model, "x.toml")


def test_descriptor_reads_the_file_named_after_the_class(monkeypatch: pytest.MonkeyPatch, tmp_path: Any) -> None:
    (tmp_path / "baselines").mkdir()
    (tmp_path / "datasets").mkdir()
    (tmp_path / "baselines" / "toy.toml").write_text(
        "[presets.default]\nsize = 0.5\ncount = 3\n[presets.more]\ncount = 9\n"
    )
    monkeypatch.setenv("ALBOT1_CONFIG_DIR", str(tmp_path))

    class Toy:
        name: ClassVar[str] = "toy"
        config_model: ClassVar[type[BaseModel]] = _Model
        presets = TomlPresets()

    assert Toy.presets == {"default": {"size": 0.5, "count": 3}, "more": {"size": 0.5, "count": 9}}
    assert Toy.presets is Toy.presets  # read once


def test_broken_toml_is_a_config_error(monkeypatch: pytest.MonkeyPatch, tmp_path: Any) -> None:
    (tmp_path / "baselines").mkdir()
    (tmp_path / "datasets").mkdir()
    (tmp_path / "baselines" / "toy.toml").write_text("[presets.default\n")
    monkeypatch.setenv("ALBOT1_CONFIG_DIR", str(tmp_path))
    with pytest.raises(ConfigError, match=r"toy.toml: not valid TOML"):
        load_presets("toy", _Model)


def test_kiss_icp_file_is_complete_and_valid() -> None:
    with preset_file("kiss-icp").open("rb") as handle:
        raw = tomllib.load(handle)
    assert set(raw["presets"]["default"]) == set(KissIcpConfig.model_fields)
    for name, values in KissIcpMapper.presets.items():
        KissIcpConfig.model_validate(values)
        assert set(values) == set(KissIcpConfig.model_fields), name


def test_kiss_icp_precedence_preset_env_override(monkeypatch: pytest.MonkeyPatch) -> None:
    default = KissIcpMapper.presets["default"]
    assert resolve_config("kiss-icp").voxel_size_m == default["voxel_size_m"]  # type: ignore[attr-defined]
    monkeypatch.setenv("ALBOT1_KISS_ICP_VOXEL_SIZE_M", "0.4")
    assert resolve_config("kiss-icp").voxel_size_m == 0.4  # type: ignore[attr-defined]
    assert resolve_config("kiss-icp", overrides={"voxel_size_m": "0.6"}).voxel_size_m == 0.6  # type: ignore[attr-defined]
    with pytest.raises(ConfigError, match=r"voxel_size_m: Input should be greater than 0"):
        resolve_config("kiss-icp", overrides={"voxel_size_m": "-1"})


class _Wide(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    size: float = Field(1.0, gt=0)
    count: int = 1
    extra_m: float = Field(1.0, gt=0)


def _config_dir(tmp_path: Any, monkeypatch: pytest.MonkeyPatch, files: dict[str, str]) -> None:
    (tmp_path / "baselines").mkdir(exist_ok=True)
    for name, text in files.items():
        (tmp_path / "baselines" / f"{name}.toml").write_text(text)
    monkeypatch.setenv("ALBOT1_CONFIG_DIR", str(tmp_path))


BASE = "[presets.default]\nsize = 0.5\ncount = 3\n[presets.x]\nsize = 2.0\n"


def test_a_method_extends_another_methods_presets(monkeypatch: pytest.MonkeyPatch, tmp_path: Any) -> None:
    """Every base preset is an extending preset with the extending file's values on top (albot1-places)."""
    own = 'extends = "base"\n[presets.default]\nextra_m = 0.2\n[presets.x]\nextra_m = 0.7\n[presets.own]\ncount = 8\n'
    _config_dir(tmp_path, monkeypatch, {"base": BASE, "wide": own})
    assert load_presets("wide", _Wide) == {
        "default": {"size": 0.5, "count": 3, "extra_m": 0.2},
        "x": {"size": 2.0, "count": 3, "extra_m": 0.7},
        "own": {"size": 0.5, "count": 8, "extra_m": 0.2},
    }
    assert preset_names("wide") == ["default", "x", "own"]


def test_extends_errors_name_the_files(monkeypatch: pytest.MonkeyPatch, tmp_path: Any) -> None:
    _config_dir(tmp_path, monkeypatch, {"base": BASE, "wide": 'extends = "base"\n[presets.default]\nextra_m = -1\n'})
    with pytest.raises(ConfigError, match=r"base.toml \+ .*wide.toml: preset 'default' is not a valid _Wide.*extra_m"):
        load_presets("wide", _Wide)
    _config_dir(tmp_path, monkeypatch, {"a": 'extends = "b"\n' + BASE, "b": 'extends = "a"\n' + BASE})
    with pytest.raises(ConfigError, match=r"presets of a -> b -> a: `extends` goes round in a circle"):
        load_presets("a", _Model)
    _config_dir(tmp_path, monkeypatch, {"c": "extends = 3\n" + BASE})
    with pytest.raises(ConfigError, match=r"c.toml: extends must name a method"):
        load_presets("c", _Model)


def test_every_method_reads_its_presets_from_one_folder() -> None:
    """One place, one rule: baselines/<method>.toml for every built-in method (Albot1 included)."""
    from albot1.methods.registry import BUILTIN_METHODS

    for spec in BUILTIN_METHODS:
        assert preset_file(spec.name).name == f"{spec.name}.toml"
        assert preset_file(spec.name).parent.name == "baselines"
