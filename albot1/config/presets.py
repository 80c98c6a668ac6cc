"""Every method's presets, read from a TOML file by one mechanism.

Why a TOML file and not a dict in the code: the numbers a method runs with
(voxel sizes, thresholds, ...) are what a researcher reads, questions and
edits, and each carries a justification that belongs beside it. The split
is therefore

* the pydantic config model holds the *types, bounds and meaning* of every
  field (a model may keep plain defaults so it can be built directly in
  code, but runs never rely on them);
* a TOML file holds the *values*: a ``[presets.default]`` table that must
  set every field of the model (checked), and optional further
  ``[presets.NAME]`` tables, each listing only what it changes relative to
  ``default``.

Where the file lives depends on who owns the values. A wrapped baseline's
file is ``baselines/<method>.toml`` (the project's editable config folder,
found by :func:`albot1.resources.find_resource`); a method that is part of
this package ships its file beside its code as package data
(``albot1/methods/albot1/presets.toml``, the thesis's values).

A mapper class opts in with ``presets: ClassVar[...] = TomlPresets()`` (a
baseline) or ``TomlPresets(package="its.package")`` (package data). The
descriptor reads the file the first time ``cls.presets`` is used (not at
import, so importing a mapper never touches the disk), merges every preset
onto ``default`` and validates each merged preset against
``cls.config_model``: a typo or out-of-range value in the file is a
:class:`~albot1.errors.ConfigError` naming the file, preset and field,
raised before any run starts.

The precedence applied later by :func:`albot1.config.resolve.resolve`
is: model < preset < env ``ALBOT1_<METHOD>_<FIELD>`` < ``--set``.
"""

from __future__ import annotations

import tomllib
from importlib.resources import files
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from albot1.config.validation import describe_errors
from albot1.errors import ConfigError
from albot1.resources import find_resource

PresetTable = dict[str, dict[str, Any]]

#: The file name of a package's own presets (``TomlPresets(package=...)``).
PACKAGE_PRESETS = "presets.toml"


def preset_file(method: str) -> Path:
    """The config file of a baseline: ``baselines/<method>.toml`` (the one place that looks it up)."""
    return find_resource("baselines", f"{method}.toml")


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
            raise ConfigError(
                f"{source}: preset {name!r} is not a valid {model.__name__}: {describe_errors(exc)}"
            ) from None
        merged[name] = preset
    return merged


def parse_preset_text(text: str, model: type[BaseModel], source: str) -> PresetTable:
    """:func:`parse_presets` of TOML text; invalid TOML is a ConfigError naming ``source``."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: not valid TOML: {exc}") from None
    return parse_presets(data, model, source)


def load_presets(method: str, model: type[BaseModel]) -> PresetTable:
    """Read and validate ``baselines/<method>.toml``."""
    path = preset_file(method)
    return parse_preset_text(path.read_text(encoding="utf-8"), model, str(path))


def load_package_presets(package: str, model: type[BaseModel]) -> PresetTable:
    """Read and validate ``presets.toml`` shipped inside ``package``."""
    resource = files(package).joinpath(PACKAGE_PRESETS)
    if not resource.is_file():
        raise ConfigError(f"{resource}: the presets of package {package} are missing (package data not installed?)")
    return parse_preset_text(resource.read_text(encoding="utf-8"), model, str(resource))


class TomlPresets:
    """Class attribute that loads ``presets`` lazily from the owner's TOML file.

    ``TomlPresets()`` reads ``baselines/<owner.name>.toml``;
    ``TomlPresets(package="a.b")`` reads ``presets.toml`` of package ``a.b``.
    The owner class must define ``name`` and ``config_model`` (as every
    :class:`~albot1.contract.Mapper` does). The table is read once per owner
    class and process.
    """

    def __init__(self, package: str | None = None) -> None:
        self.package = package
        self._cache: dict[type, PresetTable] = {}

    def __get__(self, instance: object, owner: type) -> PresetTable:
        table = self._cache.get(owner)
        if table is None:
            model: type[BaseModel] = owner.config_model  # type: ignore[attr-defined]
            if self.package is None:
                table = load_presets(owner.name, model)  # type: ignore[attr-defined]
            else:
                table = load_package_presets(self.package, model)
            self._cache[owner] = table
        return table

    def location(self, owner: type) -> str:
        """Where the owner's presets are read from (for listings and messages)."""
        if self.package is None:
            return str(preset_file(owner.name))  # type: ignore[attr-defined]
        return str(files(self.package).joinpath(PACKAGE_PRESETS))
