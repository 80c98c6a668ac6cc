"""Presets read from TOML (albot1.config.presets): baselines/<method>.toml and a package's presets.toml."""

from __future__ import annotations

import tomllib
from typing import Any, ClassVar

import pytest
from pydantic import BaseModel, ConfigDict, Field

from albot1.config.presets import TomlPresets, load_package_presets, load_presets, parse_presets, preset_file
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
        presets: ClassVar[dict[str, dict[str, Any]]] = TomlPresets()  # type: ignore[assignment]

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


def _package(tmp_path: Any, monkeypatch: pytest.MonkeyPatch, name: str, presets: str | None) -> None:
    folder = tmp_path / name
    folder.mkdir()
    (folder / "__init__.py").write_text("")
    if presets is not None:
        (folder / "presets.toml").write_text(presets)
    monkeypatch.syspath_prepend(str(tmp_path))


def test_package_presets_use_the_same_mechanism(monkeypatch: pytest.MonkeyPatch, tmp_path: Any) -> None:
    _package(
        tmp_path, monkeypatch, "toy_presets_pkg", "[presets.default]\nsize = 0.5\ncount = 3\n[presets.x]\nsize = 2.0\n"
    )

    class Toy:
        name: ClassVar[str] = "toy"
        config_model: ClassVar[type[BaseModel]] = _Model
        presets: ClassVar[dict[str, dict[str, Any]]] = TomlPresets(package="toy_presets_pkg")  # type: ignore[assignment]

    assert Toy.presets == {"default": {"size": 0.5, "count": 3}, "x": {"size": 2.0, "count": 3}}
    assert Toy.__dict__["presets"].location(Toy) == str(tmp_path / "toy_presets_pkg" / "presets.toml")


def test_package_presets_errors_name_the_file(monkeypatch: pytest.MonkeyPatch, tmp_path: Any) -> None:
    _package(tmp_path, monkeypatch, "toy_bad_pkg", "[presets.default]\nsize = 0.5\n")
    _package(tmp_path, monkeypatch, "toy_empty_pkg", None)
    with pytest.raises(ConfigError, match=r"toy_bad_pkg/presets.toml: \[presets.default\] must set every field"):
        load_package_presets("toy_bad_pkg", _Model)
    with pytest.raises(
        ConfigError, match=r"toy_empty_pkg/presets.toml: the presets of package toy_empty_pkg are missing"
    ):
        load_package_presets("toy_empty_pkg", _Model)
