"""Baseline presets read from the project's ``baselines/<method>.toml``.

Why a TOML file and not a dict in the code: the numbers a baseline runs with
(voxel sizes, thresholds, ...) are what a researcher reads, questions and
edits, and each carries a measured justification that belongs beside it.
The split is therefore

* the pydantic config model holds the *types, bounds and meaning* of every
  field (and no tuned values; a model may keep plain defaults so it can be
  built directly in code, but runs never rely on them);
* ``baselines/<method>.toml`` holds the *values*: a ``[presets.default]``
  table that must set every field of the model (checked), and optional
  further ``[presets.NAME]`` tables, each listing only what it changes
  relative to ``default``.

A mapper class opts in with ``presets: ClassVar[...] = TomlPresets()``. The
descriptor reads ``baselines/<cls.name>.toml`` the first time ``cls.presets``
is used (not at import, so importing a mapper never touches the disk), merges
every preset onto ``default`` and validates each merged preset against
``cls.config_model``: a typo or out-of-range value in the file is a
:class:`~albot1.errors.ConfigError` naming the file, preset and field,
raised before any run starts.

The precedence applied later by :func:`albot1.methods.registry.resolve_config`
is unchanged: model < preset < env ``ALBOT1_<METHOD>_<FIELD>`` < ``--set``.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from albot1.errors import ConfigError
from albot1.resources import project_file

PresetTable = dict[str, dict[str, Any]]


def preset_file(method: str) -> Path:
    """The config file of a baseline: ``baselines/<method>.toml`` in the project."""
    return project_file("baselines", f"{method}.toml")


def parse_presets(data: dict[str, Any], model: type[BaseModel], source: str) -> PresetTable:
    """Merged, validated presets from a parsed TOML document.

    ``source`` names the file in error messages. Each returned preset is
    complete (``default`` merged with the preset's own values), so it can be
    validated on its own and compared across presets.
    """
    tables = data.get("presets")
    if not isinstance(tables, dict) or not isinstance(tables.get("default"), dict):
        raise ConfigError(f"{source}: expected a [presets.default] table (and optional [presets.NAME] tables)")
    unknown_top = sorted(set(data) - {"presets"})
    if unknown_top:
        raise ConfigError(
            f"{source}: unexpected top-level key(s) {', '.join(unknown_top)}; only [presets.NAME] tables are read"
        )
    default = tables["default"]
    missing = [name for name in model.model_fields if name not in default]
    if missing:
        raise ConfigError(
            f"{source}: [presets.default] must set every field of {model.__name__}; missing: {', '.join(missing)}"
        )
    merged: PresetTable = {}
    for name, values in tables.items():
        if not isinstance(values, dict):
            raise ConfigError(f"{source}: presets.{name} must be a table of FIELD = VALUE, got {type(values).__name__}")
        preset = {**default, **values}
        try:
            model.model_validate(preset)
        except ValidationError as exc:
            problems = "; ".join(f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in exc.errors())
            raise ConfigError(f"{source}: preset {name!r} is not a valid {model.__name__}: {problems}") from None
        merged[name] = preset
    return merged


def load_presets(method: str, model: type[BaseModel]) -> PresetTable:
    """Read and validate ``baselines/<method>.toml`` (see :func:`parse_presets`)."""
    path = preset_file(method)
    try:
        with path.open("rb") as handle:
            data = tomllib.load(handle)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    return parse_presets(data, model, str(path))


class TomlPresets:
    """Class attribute that loads ``presets`` lazily from ``baselines/<owner.name>.toml``.

    The owner class must define ``name`` and ``config_model`` (as every
    :class:`~albot1.contract.Mapper` does). The table is read once per
    owner class and process.
    """

    def __init__(self) -> None:
        self._cache: dict[type, PresetTable] = {}

    def __get__(self, instance: object, owner: type) -> PresetTable:
        table = self._cache.get(owner)
        if table is None:
            table = load_presets(owner.name, owner.config_model)  # type: ignore[attr-defined]
            self._cache[owner] = table
        return table
