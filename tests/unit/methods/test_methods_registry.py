"""The method registry: typed mapper loading, every method's config through one mechanism."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, ClassVar

import pytest
from pydantic import BaseModel, ConfigDict

from albot1.config.env import UnknownEnvironmentVariableError
from albot1.config.targets import TargetError
from albot1.errors import ConfigError
from albot1.methods import registry
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.errors import UnknownMethodError
from albot1.methods.registry import (
    MethodRegistry,
    MethodSpec,
    load_mapper_class,
    method_registry,
    parse_overrides,
    resolve_config,
    resolve_method_config,
)


class PlacesConfig(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    radius_m: float = 1.0


class PlacesMapper:
    """A stand-in for a future method whose name extends "albot1"."""

    name: ClassVar[str] = "albot1-places"
    config_model: ClassVar[type[BaseModel]] = PlacesConfig
    presets: ClassVar[dict[str, dict[str, Any]]] = {"default": {}}

    def process(self, frame: Any) -> None: ...

    def finish(self) -> Any: ...


NOT_A_MAPPER = 3


@pytest.fixture(autouse=True)
def _clean_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [n for n in os.environ if n.upper().startswith(("ALBOT1_ALBOT1_", "ALBOT1_KISS_ICP_"))]:
        monkeypatch.delenv(name)


def test_every_registered_method_has_toml_presets_with_a_complete_default() -> None:
    for spec in method_registry():
        if not spec.available():
            continue
        cls = spec.load_class()
        assert set(cls.presets["default"]) == set(cls.config_model.model_fields), spec.name
        for preset in cls.presets:
            assert resolve_config(spec.name, preset) == cls.config_model.model_validate(cls.presets[preset])


def test_env_override_of_a_real_albot1_field(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_ALBOT1_CORNER_MIN_ANGLE_DEG", "45")
    resolved = resolve_method_config("albot1", "exact")
    assert resolved.config.corner_min_angle_deg == 45.0  # type: ignore[attr-defined]
    assert resolved.config.motion_model == "exact"  # type: ignore[attr-defined]
    assert resolved.sources["corner_min_angle_deg"] == "env ALBOT1_ALBOT1_CORNER_MIN_ANGLE_DEG"
    assert resolved.sources["motion_model"] == "preset exact"
    assert resolved.sources["max_range_m"] == "preset default"


def test_unknown_env_name_is_rejected(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_KISS_ICP_VOXEL_SIZE", "0.2")
    with pytest.raises(UnknownEnvironmentVariableError) as info:
        resolve_config("kiss-icp")
    message = str(info.value)
    assert message.startswith(
        "environment variable ALBOT1_KISS_ICP_VOXEL_SIZE names no config field of kiss-icp; "
        "did you mean ALBOT1_KISS_ICP_VOXEL_SIZE_M? valid names: ALBOT1_KISS_ICP_VOXEL_SIZE_M, "
    )
    assert "ALBOT1_KISS_ICP_MAP_VOXEL_M" in message


def test_nested_method_prefixes(monkeypatch: pytest.MonkeyPatch) -> None:
    """``albot1`` reads ALBOT1_ALBOT1_*; a registered ``albot1-places`` owns ALBOT1_ALBOT1_PLACES_*."""
    monkeypatch.setenv("ALBOT1_ALBOT1_PLACES_RADIUS_M", "2.5")
    # the registered albot1-places owns the prefix: albot1 leaves the variable to it, and it has no such field
    assert resolve_config("albot1") == resolve_config("albot1", "default", {})
    with pytest.raises(UnknownEnvironmentVariableError, match="ALBOT1_ALBOT1_PLACES_RADIUS_M names no config field"):
        resolve_config("albot1-places")
    stand_in = method_registry().with_methods(MethodSpec("albot1-places", f"{__name__}:PlacesMapper"))
    assert resolve_config("albot1", registry=stand_in) == resolve_config("albot1", "default", {})
    assert resolve_config("albot1-places", registry=stand_in) == PlacesConfig(radius_m=2.5)
    monkeypatch.setenv("ALBOT1_ALBOT1_MAX_RANGE_M", "12")
    assert resolve_config("albot1", registry=stand_in).max_range_m == 12.0  # type: ignore[attr-defined]
    assert resolve_config("albot1-places", registry=stand_in) == PlacesConfig(radius_m=2.5)


def test_set_wins_over_env_wins_over_preset(monkeypatch: pytest.MonkeyPatch) -> None:
    assert resolve_config("albot1", "literal").delete_margin_from == "boundary"  # type: ignore[attr-defined]
    monkeypatch.setenv("ALBOT1_ALBOT1_DELETE_MARGIN_FROM", "surfaces")
    assert resolve_config("albot1", "literal").delete_margin_from == "surfaces"  # type: ignore[attr-defined]
    overrides = parse_overrides(["delete_margin_from=boundary"])
    resolved = resolve_method_config("albot1", "literal", overrides)
    assert resolved.config.delete_margin_from == "boundary"  # type: ignore[attr-defined]
    assert resolved.sources["delete_margin_from"] == "--set"


def test_load_mapper_class_checks_the_contract() -> None:
    assert load_mapper_class("albot1.methods.albot1.mapping.mapper:Albot1Mapper") is Albot1Mapper
    with pytest.raises(TargetError, match=r"NOT_A_MAPPER: expected a class, found int"):
        load_mapper_class(f"{__name__}:NOT_A_MAPPER")
    with pytest.raises(
        TargetError, match=r"PlacesConfig: not a mapper class, it lacks name, config_model, presets, process, finish"
    ):
        load_mapper_class(f"{__name__}:PlacesConfig")


def test_bad_targets_are_refused_when_the_spec_is_made() -> None:
    with pytest.raises(TargetError, match=r"expected 'module:Class'.*got 'nocolon'"):
        MethodSpec("x", "nocolon")


def test_error_class_must_be_an_exception(monkeypatch: pytest.MonkeyPatch) -> None:
    spec = MethodSpec("x", f"{__name__}:PlacesMapper", error_class=f"{__name__}:PlacesMapper")
    with pytest.raises(TargetError, match="expected an exception class"):
        spec.load_error_class()


def test_unknown_method_is_a_config_error() -> None:
    with pytest.raises(UnknownMethodError, match="unknown method 'nope'; expected one of: odometry, albot1"):
        registry.get_method("nope")
    assert issubclass(UnknownMethodError, ConfigError)


@pytest.mark.parametrize(
    ("typed", "suggested"),
    [("kiss_icp", "kiss-icp"), ("KISS-ICP", "kiss-icp"), ("gtsam_grap", "gtsam-graph"), ("albot", "albot1")],
)
def test_unknown_method_suggests_the_closest(typed: str, suggested: str) -> None:
    with pytest.raises(UnknownMethodError, match=rf"unknown method '{typed}' \(did you mean '{suggested}'"):
        registry.get_method(typed)


def test_the_registry_is_immutable_and_one_object_per_process() -> None:
    built = method_registry()
    assert method_registry() is built
    with pytest.raises(TypeError):
        built.specs["x"] = MethodSpec("x", f"{__name__}:PlacesMapper")  # type: ignore[index]
    bigger = built.with_methods(MethodSpec("x", f"{__name__}:PlacesMapper"))
    assert "x" in bigger and "x" not in built and len(bigger) == len(built) + 1


def test_a_name_registered_twice_is_refused() -> None:
    spec = MethodSpec("x", f"{__name__}:PlacesMapper")
    with pytest.raises(UnknownMethodError, match="method 'x' is registered twice"):
        MethodRegistry.of([spec, spec])


def test_the_registry_is_read_again_only_when_what_it_was_read_from_changed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A forked bench cell keeps its server's registry unless a distribution was installed, changed or removed."""
    from albot1.methods.plugins import ENTRY_POINT_GROUP

    def names() -> set[str]:
        return {spec.name for spec in registry.method_registry()}

    site = tmp_path / "site"
    site.mkdir()
    monkeypatch.syspath_prepend(str(site))
    old = (1_000_000_000, 1_000_000_000)  # times well before any change below (the file system's are coarse)
    os.utime(site, ns=old)
    try:
        registry.method_registry.cache_clear()
        first = registry.method_registry()
        registry.forget_registry_if_changed()
        assert registry.method_registry() is first  # nothing changed: kept, no metadata read
        info = site / "late_plugin-0.1.dist-info"  # installed into a folder on the path
        info.mkdir()
        (info / "METADATA").write_text("Metadata-Version: 2.1\nName: late-plugin\nVersion: 0.1\n")
        points = info / "entry_points.txt"
        points.write_text(f"[{ENTRY_POINT_GROUP}]\nlate = late_plugin:Mapper\n")
        os.utime(points, ns=old)
        registry.forget_registry_if_changed()
        assert "late" in names()
        second = registry.method_registry()
        points.write_text(f"[{ENTRY_POINT_GROUP}]\nlater = late_plugin:Mapper\n")  # rewritten in place
        registry.forget_registry_if_changed()
        assert registry.method_registry() is not second
        assert "later" in names() and "late" not in names()
        third = registry.method_registry()
        monkeypatch.syspath_prepend(str(tmp_path / "elsewhere"))  # another import path
        registry.forget_registry_if_changed()
        assert registry.method_registry() is not third
    finally:
        registry.method_registry.cache_clear()
