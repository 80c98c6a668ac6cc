"""Environment overrides ALBOT1_<METHOD>_<FIELD> (albot1.config.env, albot1.config.resolve)."""

from __future__ import annotations

import os
from typing import Literal

import pytest
from pydantic import BaseModel, ConfigDict, Field

from albot1.config.env import UnknownEnvironmentVariableError, env_values, method_prefix, owner_of
from albot1.config.resolve import resolve
from albot1.errors import ConfigError


class _Toy(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    size_m: float = Field(1.0, gt=0)
    mode: Literal["a", "b"] = "a"
    on: bool = True


PRESETS = {"default": {"size_m": 2.0, "mode": "a", "on": True}, "big": {"size_m": 5.0, "mode": "a", "on": True}}


@pytest.fixture(autouse=True)
def _clean_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [n for n in os.environ if n.upper().startswith("ALBOT1_TOY")]:
        monkeypatch.delenv(name)


def test_prefix_spelling() -> None:
    assert method_prefix("kiss-icp") == "ALBOT1_KISS_ICP_"
    assert method_prefix("albot1") == "ALBOT1_ALBOT1_"
    assert method_prefix("albot1-places") == "ALBOT1_ALBOT1_PLACES_"


def test_longest_prefix_owns_a_variable() -> None:
    prefixes = ["ALBOT1_ALBOT1_", "ALBOT1_ALBOT1_PLACES_", "ALBOT1_KISS_ICP_"]
    assert owner_of("ALBOT1_ALBOT1_PLACES_RADIUS_M", prefixes) == "ALBOT1_ALBOT1_PLACES_"
    assert owner_of("ALBOT1_ALBOT1_MAX_RANGE_M", prefixes) == "ALBOT1_ALBOT1_"
    assert owner_of("ALBOT1_DATA_DIR", prefixes) is None


def test_a_real_field_is_read_and_wins_over_the_preset(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_TOY_SIZE_M", "0.25")
    monkeypatch.setenv("ALBOT1_TOY_ON", "false")
    assert env_values(_Toy, "ALBOT1_TOY_") == {
        "size_m": ("ALBOT1_TOY_SIZE_M", "0.25"),
        "on": ("ALBOT1_TOY_ON", "false"),
    }
    resolved = resolve(_Toy, PRESETS, "big", env_prefix="ALBOT1_TOY_", owner="toy")
    assert resolved.config == _Toy(size_m=0.25, mode="a", on=False)
    assert resolved.sources == {"size_m": "env ALBOT1_TOY_SIZE_M", "mode": "preset default", "on": "env ALBOT1_TOY_ON"}


def test_explicit_overrides_win_over_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_TOY_SIZE_M", "0.25")
    resolved = resolve(_Toy, PRESETS, "default", env_prefix="ALBOT1_TOY_", overrides={"size_m": "7"})
    assert resolved.config.size_m == 7.0
    assert resolved.sources["size_m"] == "--set"


def test_unknown_name_is_rejected_naming_it_and_the_valid_names(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_TOY_SIZE", "0.2")  # the field is size_m
    with pytest.raises(UnknownEnvironmentVariableError) as info:
        resolve(_Toy, PRESETS, "default", env_prefix="ALBOT1_TOY_", owner="toy")
    assert str(info.value) == (
        "environment variable ALBOT1_TOY_SIZE names no config field of toy; did you mean ALBOT1_TOY_SIZE_M? "
        "valid names: ALBOT1_TOY_SIZE_M, ALBOT1_TOY_MODE, ALBOT1_TOY_ON"
    )


def test_nested_prefixes_leave_the_longer_methods_variables_alone(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_TOY_PLACES_RADIUS_M", "3")
    # With a method "toy-places" registered, the variable is its business, not toy's.
    resolved = resolve(_Toy, PRESETS, "default", env_prefix="ALBOT1_TOY_", other_prefixes=["ALBOT1_TOY_PLACES_"])
    assert resolved.config == _Toy(size_m=2.0)
    # Without it, the variable is under toy's prefix and names none of its fields.
    with pytest.raises(UnknownEnvironmentVariableError, match="ALBOT1_TOY_PLACES_RADIUS_M names no config field"):
        resolve(_Toy, PRESETS, "default", env_prefix="ALBOT1_TOY_")


def test_project_settings_are_never_method_variables(monkeypatch: pytest.MonkeyPatch) -> None:
    # A method named "data" would own ALBOT1_DATA_*, but ALBOT1_DATA_DIR stays the dataset folder.
    monkeypatch.setenv("ALBOT1_DATA_DIR", "/nowhere")
    assert env_values(_Toy, "ALBOT1_DATA_") == {}


def test_a_bad_value_names_its_variable(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_TOY_MODE", "c")
    with pytest.raises(ConfigError, match=r"mode: Input should be 'a' or 'b', found c \(from env ALBOT1_TOY_MODE\)"):
        resolve(_Toy, PRESETS, "default", env_prefix="ALBOT1_TOY_", owner="toy")


def test_unknown_preset_lists_the_known_ones() -> None:
    with pytest.raises(ConfigError, match=r"^method 'toy' has no preset 'huge'; expected one of: default, big$"):
        resolve(_Toy, PRESETS, "huge", env_prefix="ALBOT1_TOY_", owner="toy")


def test_sources_of_a_partial_dict_preset() -> None:
    """A preset given as a partial dict (not from TOML) leaves the other fields to the model."""
    resolved = resolve(_Toy, {"default": {}, "b": {"mode": "b"}}, "b", env_prefix="ALBOT1_TOY_")
    assert resolved.config == _Toy(mode="b")
    assert resolved.sources == {"size_m": "model default", "mode": "preset b", "on": "model default"}


def test_a_value_from_the_environment_is_said_once(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    from albot1.config import resolve as resolve_module

    monkeypatch.setattr(resolve_module, "_said", set(), raising=False)
    monkeypatch.setenv("ALBOT1_TOY_SIZE_M", "0.25")
    with caplog.at_level("WARNING", logger="albot1.config.resolve"):
        for _ in range(3):  # a bench resolves every cell's config
            resolve(_Toy, PRESETS, "big", env_prefix="ALBOT1_TOY_", owner="toy")
        resolve(_Toy, PRESETS, "big", env_prefix="ALBOT1_TOY_", owner="toy", overrides={"size_m": "7"})  # not used
    assert [r.getMessage() for r in caplog.records] == ["toy: size_m = 0.25 from the environment (ALBOT1_TOY_SIZE_M)"]


def test_a_variable_no_method_owns_is_said_once(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """``ALBOT1_KISSICP_VOXEL_SIZE_M`` (the method misspelt) was ignored without a word (the preset's 0.15 m)."""
    from albot1.methods import registry

    monkeypatch.setattr(registry, "_said_stray", set(), raising=False)
    monkeypatch.setenv("ALBOT1_KISSICP_VOXEL_SIZE_M", "2")
    monkeypatch.setenv("ALBOT1_DECODED_CACHE", "off")  # a setting: never said
    with caplog.at_level("WARNING", logger="albot1.methods.registry"):
        for _ in range(2):
            config = registry.resolve_config("kiss-icp")
    assert config.voxel_size_m == 0.15  # type: ignore[attr-defined]  # the preset's
    assert [r.getMessage() for r in caplog.records] == [
        "environment variable ALBOT1_KISSICP_VOXEL_SIZE_M names no registered method's field nor a setting of "
        "albot1-bench (ignored); did you mean ALBOT1_KISS_ICP_VOXEL_SIZE_M?"
    ]


def test_the_known_settings_are_every_setting_the_sources_read() -> None:
    """Every ``"ALBOT1_..."`` name in the package, setup.py and the benchmarks is a setting or a method's variable."""
    import re
    from pathlib import Path

    from albot1.config.env import OTHER_SETTINGS, SETTINGS_VARIABLES
    from albot1.methods.registry import method_registry

    root = Path(__file__).resolve().parents[3]
    sources = [*root.glob("albot1/**/*.py"), root / "setup.py", *root.glob("benchmarks/*.py")]
    found = {m for path in sources for m in re.findall(r"[\"'](ALBOT1_[A-Z0-9_]*[A-Z0-9])[\"']", path.read_text())}
    prefixes = [spec.env_prefix for spec in method_registry()]
    settings = {name for name in found if owner_of(name, prefixes) is None}
    assert settings == SETTINGS_VARIABLES | OTHER_SETTINGS
