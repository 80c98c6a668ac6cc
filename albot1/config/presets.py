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

Beside the presets a file records where its values came from: a
``[tuned_on]`` table maps a preset to the dataset names its values were
chosen on by looking at their scores (the *held-in* datasets; a preset the
table does not name has ``default``'s). A number measured on one of them is
not evidence of how the method generalises, so the reports mark it
(:func:`tuned_on`, ``albot1.report.tuning``). The table is data, not config:
it never enters a run's config or its key.
"""

from __future__ import annotations

import inspect
import tomllib
from importlib.resources import files
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from albot1.config.validation import describe_errors
from albot1.errors import ConfigError
from albot1.resources import find_resource

PresetTable = dict[str, dict[str, Any]]
#: preset name -> the datasets its values were tuned on (``[tuned_on]`` of a preset file)
TunedOnTable = dict[str, tuple[str, ...]]

#: The top-level table of a preset file that names the held-in datasets of each preset.
TUNED_ON = "tuned_on"

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
    unknown_top = sorted(set(data) - {"presets", TUNED_ON})
    if unknown_top:
        raise ConfigError(
            f"{source}: unexpected top-level key(s) {', '.join(unknown_top)}; only [presets.NAME] tables and "
            f"[{TUNED_ON}] are read"
        )
    parse_tuned_on(data, source)
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


def parse_tuned_on(data: dict[str, Any], source: str) -> TunedOnTable | None:
    """The ``[tuned_on]`` table of a parsed preset file (None when the file has none), validated.

    Keys are preset names of the file (``default`` required), values lists of
    distinct, non-empty dataset names (an empty list: tuned on no dataset).
    """
    table = data.get(TUNED_ON)
    if table is None:
        return None
    expected = f"expected [{TUNED_ON}] PRESET = [dataset names its values were chosen on]"
    if not isinstance(table, dict):
        raise ConfigError(f"{source}: {TUNED_ON}: {expected}, got {type(table).__name__}")
    declared = data.get("presets")
    presets: dict[str, Any] = declared if isinstance(declared, dict) else {}
    if "default" not in table:
        raise ConfigError(f"{source}: [{TUNED_ON}] must name the datasets of preset 'default'; {expected}")
    out: TunedOnTable = {}
    for preset, names in table.items():
        if preset not in presets:
            raise ConfigError(f"{source}: [{TUNED_ON}] names preset {preset!r}, which the file does not define")
        if not isinstance(names, list) or not all(isinstance(n, str) and n.strip() for n in names):
            raise ConfigError(f"{source}: {TUNED_ON}.{preset}: {expected}, got {names!r}")
        if len(set(names)) != len(names):
            raise ConfigError(f"{source}: {TUNED_ON}.{preset}: a dataset is named twice in {names!r}")
        out[preset] = tuple(names)
    return out


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


def _document(path_or_resource: Any, source: str) -> dict[str, Any]:
    try:
        return tomllib.loads(path_or_resource.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: not valid TOML: {exc}") from None


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
        self._tuned: dict[type, TunedOnTable | None] = {}

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

    def tuned_on(self, owner: type) -> TunedOnTable | None:
        """The owner file's ``[tuned_on]`` table (None: the file records none); read once per owner class."""
        if owner not in self._tuned:
            self.__get__(None, owner)  # validates the whole file first
            resource: Any = preset_file(owner.name) if self.package is None else self._resource()  # type: ignore[attr-defined]
            self._tuned[owner] = parse_tuned_on(_document(resource, str(resource)), str(resource))
        return self._tuned[owner]

    def _resource(self) -> Any:
        assert self.package is not None
        return files(self.package).joinpath(PACKAGE_PRESETS)

    def location(self, owner: type) -> str:
        """Where the owner's presets are read from (for listings and messages)."""
        if self.package is None:
            return str(preset_file(owner.name))  # type: ignore[attr-defined]
        return str(files(self.package).joinpath(PACKAGE_PRESETS))


def tuned_on_table(owner: type) -> TunedOnTable | None:
    """``owner``'s ``[tuned_on]`` table (preset -> datasets), or None when its presets record none."""
    descriptor = inspect.getattr_static(owner, "presets", None)
    return descriptor.tuned_on(owner) if isinstance(descriptor, TomlPresets) else None


def tuned_on(owner: type, preset: str) -> tuple[str, ...] | None:
    """The datasets ``owner``'s ``preset`` was tuned on; None when its preset file does not record them.

    A preset that ``[tuned_on]`` does not name inherits ``default``'s list
    (its values are ``default``'s but for what it changes).
    """
    table = tuned_on_table(owner)
    if table is None:
        return None
    return table.get(preset, table["default"])
