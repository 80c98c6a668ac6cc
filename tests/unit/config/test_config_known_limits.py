"""Known limits recorded in preset files: the ``[known_limits.PRESET]`` table (albot1.config.known_limits)."""

from __future__ import annotations

from typing import Any

import pytest
from pydantic import BaseModel, ConfigDict

from albot1.config.known_limits import known_limit, parse_known_limits
from albot1.config.presets import load_known_limits, parse_presets
from albot1.data import catalog
from albot1.errors import ConfigError
from albot1.methods.registry import load_mapper_class, method_registry


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    size: float = 1.0


def _doc(limits: Any) -> dict[str, Any]:
    return {"presets": {"default": {"size": 1.0}, "big": {"size": 2.0}}, "known_limits": limits}


def test_limits_are_read_per_preset_and_a_preset_not_naming_a_dataset_has_defaults() -> None:
    data = _doc({"default": {"aces": "diverges  at scan 5 (docs)"}, "big": {"intel": "too slow"}})
    assert parse_presets(data, _Model, "x.toml")["big"] == {"size": 2.0}  # the table is not a preset
    table = parse_known_limits(data, "x.toml")
    assert table == {"default": {"aces": "diverges at scan 5 (docs)"}, "big": {"intel": "too slow"}}
    assert known_limit(table, "big", "intel") == "too slow"
    assert known_limit(table, "big", "aces") == "diverges at scan 5 (docs)"
    assert known_limit(table, "small", "aces") == "diverges at scan 5 (docs)"
    assert known_limit(table, "default", "intel") is None
    assert known_limit(None, "default", "aces") is None
    assert parse_known_limits({"presets": {"default": {}}}, "x.toml") is None


@pytest.mark.parametrize(
    ("limits", "message"),
    [
        ({"fast": {"aces": "x"}}, r"x.toml: \[known_limits\] names preset 'fast', which the file does not define"),
        ({"default": "aces"}, r"x.toml: known_limits.default: expected .* got 'aces'"),
        ({"default": {"aces": ""}}, r"known_limits.default.aces: expected .*single line"),
        ({"default": {"aces": "a\nb"}}, r"known_limits.default.aces: expected .*single line"),
        ({"default": {"aces": 3}}, r"known_limits.default.aces: expected"),
        (["aces"], r"x.toml: known_limits: expected .* got list"),
    ],
)
def test_a_bad_known_limits_table_is_an_error_of_the_file(limits: Any, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        parse_presets(_doc(limits), _Model, "x.toml")


def test_every_recorded_limit_names_a_catalog_dataset() -> None:
    known = set(catalog.names())
    for name, spec in method_registry().specs.items():
        table = load_known_limits(load_mapper_class(spec.target).name)
        for preset, limits in (table or {}).items():
            assert set(limits) <= known, f"{name}.{preset}: {sorted(set(limits) - known)} not in the catalog"
