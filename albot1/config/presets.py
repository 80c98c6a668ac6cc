"""Every method's presets, read from one TOML file per method by one mechanism.

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

One place, one rule: the file of method ``M`` is ``baselines/M.toml`` (the
project's config folder, shipped in the wheel and overridable file by file
from ``ALBOT1_CONFIG_DIR``; :func:`albot1.resources.find_resource`), for a
wrapped baseline and for Albot1 alike. The folder keeps its historical name.

A method that runs another inside it says so with a top-level
``extends = "OTHER"``: its presets are then OTHER's presets with its own
tables merged onto those of the same name (``albot1-places`` extends
``albot1``: every chapter-3 preset is a places preset, with the places
fields on top, so the two cannot drift apart).

A mapper class opts in with ``presets = TomlPresets()``. The descriptor
reads the file the first time ``cls.presets`` is used (not at import, so
importing a mapper never touches the disk), merges every preset onto
``default`` and validates each merged preset against ``cls.config_model``:
a typo or out-of-range value in the file is a
:class:`~albot1.errors.ConfigError` naming the file, preset and field,
raised before any run starts. Every entry point (``albot1 run``, the bench,
``albot1 evaluate``) resolves a preset name the same way
(:func:`albot1.config.resolve.resolve`), with no per-command renaming.

The precedence applied later by :func:`albot1.config.resolve.resolve`
is: model < preset < env ``ALBOT1_<METHOD>_<FIELD>`` < ``--set``.

Beside the presets a file records where its values came from: a
``[tuned_on]`` table maps a preset to the dataset names its values were
chosen on by looking at their scores (the *held-in* datasets; a preset the
table does not name has ``default``'s). A number measured on one of them is
not evidence of how the method generalises, so the reports mark it
(:func:`tuned_on`, ``albot1.report.tuning``). The table is data, not config:
it never enters a run's config or its key. A file that
``extends`` another adds its held-in datasets to the other's, preset by preset.
A ``[known_limits.PRESET]`` table records what was found about a log the
method fails on (:mod:`albot1.config.known_limits`); the standard page prints
it beside that log's failed row.
"""

from __future__ import annotations

import inspect
import tomllib
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from albot1.config.known_limits import KNOWN_LIMITS, KnownLimitsTable, parse_known_limits
from albot1.config.validation import describe_errors
from albot1.errors import ConfigError
from albot1.resources import find_resource

PresetTable = dict[str, dict[str, Any]]
#: preset name -> the datasets its values were tuned on (``[tuned_on]`` of a preset file)
TunedOnTable = dict[str, tuple[str, ...]]

#: The top-level table of a preset file that names the held-in datasets of each preset.
TUNED_ON = "tuned_on"

#: The top-level key of a presets file that builds on another method's presets.
EXTENDS = "extends"


def preset_file(method: str) -> Path:
    """The presets file of ``method``: ``baselines/<method>.toml`` (the one place that looks it up)."""
    return find_resource("baselines", f"{method}.toml")


def _tables(data: dict[str, Any], source: str) -> dict[str, dict[str, Any]]:
    """The ``[presets.NAME]`` tables of a parsed file (``default`` required), checked for shape."""
    tables = data.get("presets")
    if not isinstance(tables, dict) or not isinstance(tables.get("default"), dict):
        raise ConfigError(f"{source}: expected a [presets.default] table (and optional [presets.NAME] tables)")
    unknown_top = sorted(set(data) - {"presets", EXTENDS, TUNED_ON, KNOWN_LIMITS})
    if unknown_top:
        raise ConfigError(
            f"{source}: unexpected top-level key(s) {', '.join(unknown_top)}; only [presets.NAME] tables, "
            f'[{TUNED_ON}], [{KNOWN_LIMITS}.PRESET] and `{EXTENDS} = "METHOD"` are read'
        )
    parse_tuned_on(data, source)
    parse_known_limits(data, source)
    for name, values in tables.items():
        if not isinstance(values, dict):
            raise ConfigError(f"{source}: presets.{name} must be a table of FIELD = VALUE, got {type(values).__name__}")
    return tables


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


def _merge(base: dict[str, dict[str, Any]], tables: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Each preset of an extending file: the base preset of its name (else base ``default``), then the file's
    ``default``, then its own preset of that name."""
    return {
        name: {**base.get(name, base["default"]), **tables["default"], **tables.get(name, {})}
        for name in [*base, *(n for n in tables if n not in base)]
    }


def parse_presets(
    data: dict[str, Any], model: type[BaseModel], source: str, base: dict[str, dict[str, Any]] | None = None
) -> PresetTable:
    """Merged, validated presets from a parsed TOML document.

    ``source`` names the file in error messages. ``base`` holds the merged
    presets of the method this file extends (``extends``): each preset is
    then the base preset of its name (else the base ``default``) with this
    file's preset of that name (else its ``default``) on top. Each returned
    preset is complete, so it can be validated on its own and compared
    across presets.
    """
    tables = _tables(data, source)
    if base is None:
        own_default = tables["default"]
        layers = {name: {**own_default, **values} for name, values in tables.items()}
    else:
        layers = _merge(base, tables)
    missing = [name for name in model.model_fields if name not in layers["default"]]
    if missing:
        raise ConfigError(
            f"{source}: [presets.default] must set every field of {model.__name__}; missing: {', '.join(missing)}"
        )
    merged: PresetTable = {}
    for name, preset in layers.items():
        try:
            model.model_validate(preset)
        except ValidationError as exc:
            raise ConfigError(
                f"{source}: preset {name!r} is not a valid {model.__name__}: {describe_errors(exc)}"
            ) from None
        merged[name] = preset
    return merged


def _read(path: Path) -> dict[str, Any]:
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None


def parse_preset_text(text: str, model: type[BaseModel], source: str) -> PresetTable:
    """:func:`parse_presets` of TOML text; invalid TOML is a ConfigError naming ``source``."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: not valid TOML: {exc}") from None
    return parse_presets(data, model, source)


def _raw_chain(method: str, seen: tuple[str, ...] = ()) -> tuple[dict[str, dict[str, Any]], list[Path]]:
    """The unvalidated merged tables of ``method`` (following ``extends``) and the files read, base first."""
    if method in seen:
        raise ConfigError(f"presets of {' -> '.join([*seen, method])}: `{EXTENDS}` goes round in a circle")
    path = preset_file(method)
    data = _read(path)
    tables = _tables(data, str(path))
    parent = data.get(EXTENDS)
    if parent is None:
        return {name: {**tables["default"], **values} for name, values in tables.items()}, [path]
    if not isinstance(parent, str):
        raise ConfigError(f"{path}: {EXTENDS} must name a method (a string), got {parent!r}")
    base, files = _raw_chain(parent, (*seen, method))
    return _merge(base, tables), [*files, path]


def load_presets(method: str, model: type[BaseModel]) -> PresetTable:
    """Read and validate the presets of ``method`` (``baselines/<method>.toml``, following ``extends``)."""
    path = preset_file(method)
    data = _read(path)
    parent = data.get(EXTENDS)
    if parent is None:
        return parse_presets(data, model, str(path))
    if not isinstance(parent, str):
        raise ConfigError(f"{path}: {EXTENDS} must name a method (a string), got {parent!r}")
    base, files = _raw_chain(parent, (method,))
    return parse_presets(data, model, " + ".join(str(f) for f in [*files, path]), base)


def preset_names(method: str) -> list[str]:
    """The preset names of ``method`` read from its file(s) alone: no class imported, nothing validated."""
    data = _read(preset_file(method))
    names = list(_tables(data, str(preset_file(method))))
    parent = data.get(EXTENDS)
    if isinstance(parent, str):
        base = preset_names(parent)
        names = [*base, *(n for n in names if n not in base)]
    return names


class TomlPresets:
    """Class attribute that loads ``presets`` lazily from the owner's file, ``baselines/<owner.name>.toml``.

    The owner class must define ``name`` and ``config_model`` (as every
    :class:`~albot1.contract.Mapper` does). The table is read once per owner
    class and process.
    """

    def __init__(self) -> None:
        self._cache: dict[type, PresetTable] = {}
        self._tuned: dict[type, TunedOnTable | None] = {}

    def __get__(self, instance: object, owner: type[Any]) -> PresetTable:
        table = self._cache.get(owner)
        if table is None:
            table = load_presets(owner.name, owner.config_model)
            self._cache[owner] = table
        return table

    def location(self, owner: type[Any]) -> str:
        """Where the owner's presets are read from (for listings and messages)."""
        return str(preset_file(owner.name))

    def tuned_on(self, owner: type[Any]) -> TunedOnTable | None:
        """The owner file's ``[tuned_on]`` table (None: the file records none); read once per owner class."""
        if owner not in self._tuned:
            self.__get__(None, owner)  # validates the whole file (and what it extends) first
            self._tuned[owner] = load_tuned_on(owner.name)
        return self._tuned[owner]


def load_tuned_on(method: str) -> TunedOnTable | None:
    """``[tuned_on]`` of ``method``'s file; with ``extends``, the base's held-in datasets plus its own, per preset.

    None when a file of the chain records none (the tuning is then not known).
    """
    path = preset_file(method)
    data = _read(path)
    own = parse_tuned_on(data, str(path))
    parent = data.get(EXTENDS)
    if own is None or not isinstance(parent, str):
        return own
    base = load_tuned_on(parent)
    if base is None:
        return None
    return {
        name: tuple(dict.fromkeys([*base.get(name, base["default"]), *own.get(name, own["default"])]))
        for name in [*base, *(n for n in own if n not in base)]
    }


def load_known_limits(method: str) -> KnownLimitsTable | None:
    """``[known_limits]`` of ``method``'s file (:mod:`albot1.config.known_limits`); None when it has none.

    Not inherited through ``extends``: a finding is about the runs of the
    method that file configures.
    """
    path = preset_file(method)
    return parse_known_limits(_read(path), str(path))


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
