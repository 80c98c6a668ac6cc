"""A method's effective config: model defaults < preset < environment < explicit overrides.

The order is the one a user expects from the most general to the most
specific statement: the model says what a field means (and may carry a
plain default), the preset file says what the method runs with, an
environment variable changes it for a whole shell session or job, and
``--set FIELD=VALUE`` (or a benchmark suite's ``set``) for one run.

Besides the validated config, :func:`resolve` says where each field's value
came from, so a result can be traced to the file, variable or flag that set
it, and an invalid value's message names its origin.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from pydantic import BaseModel, ValidationError

from albot1.config.env import env_values
from albot1.config.numbers import is_number
from albot1.config.suggest import did_you_mean
from albot1.config.validation import describe_errors
from albot1.errors import ConfigError

ModelT = TypeVar("ModelT", bound=BaseModel)

log = logging.getLogger(__name__)
#: The environment values already said in this process (a bench resolves each cell's config).
_said: set[tuple[str, str, str]] = set()

#: Origin of a value that only the config model sets (a preset given as a partial dict).
FROM_MODEL = "model default"
#: Origin of an explicit override (``--set`` or a suite's ``set``).
FROM_OVERRIDE = "--set"


@dataclass(frozen=True)
class ResolvedConfig(Generic[ModelT]):
    """The validated config and, per field, where its value came from.

    ``sources`` values: ``"model default"``, ``"preset NAME"`` (the preset's
    own value), ``"preset default"`` (inherited from the default preset),
    ``"env VARIABLE"`` or ``"--set"``.
    """

    config: ModelT
    sources: dict[str, str]


def preset_sources(presets: Mapping[str, Mapping[str, Any]], preset: str, fields: Iterable[str]) -> dict[str, str]:
    """Where each field of ``presets[preset]`` comes from: the preset itself, ``default``, or the model.

    A preset "sets" a field when its value differs from the ``default``
    preset's (TOML presets are stored merged onto ``default``, so presence
    alone would say nothing).
    """
    chosen = presets[preset]
    default = presets.get("default", {})
    out = {}
    for name in fields:
        if name in chosen and (preset == "default" or name not in default or chosen[name] != default[name]):
            out[name] = f"preset {preset}"
        elif name in default:
            out[name] = "preset default"
        else:
            out[name] = FROM_MODEL
    return out


def resolve(
    model: type[ModelT],
    presets: Mapping[str, Mapping[str, Any]],
    preset: str,
    *,
    env_prefix: str,
    other_prefixes: Iterable[str] = (),
    overrides: Mapping[str, Any] | None = None,
    owner: str = "",
    override_origin: str = FROM_OVERRIDE,
    typed_overrides: bool = False,
) -> ResolvedConfig[ModelT]:
    """Validate ``model`` from ``presets[preset]``, the environment and ``overrides`` (highest last).

    ``owner`` names the method in messages; ``override_origin`` says where ``overrides`` came from
    (``--set``, or a suite's ``set``), so that a rejected one is traced to what the user wrote. Raises
    ConfigError for an unknown preset, an environment variable that names no field, or a value the model
    rejects (the message names the field and where its value came from).

    A number given as text (an environment variable, ``--set``) must be :func:`is_number` text: pydantic's lax
    conversion would read ``1_0`` as 10 and ``１`` as 1. ``typed_overrides``: ``overrides`` come typed (a
    suite's TOML ``set``), so they must have the field's type as written: a boolean or a string is not a
    number, ``2.0`` is not an int, a number is not a boolean (an int for a float field is fine).
    """
    label = owner or model.__name__
    if preset not in presets:
        raise ConfigError(
            f"method {label!r} has no preset {preset!r}{did_you_mean(preset, list(presets))}; "
            f"expected one of: {', '.join(presets)}"
        )
    sources = preset_sources(presets, preset, model.model_fields)
    values: dict[str, Any] = dict(presets[preset])
    for name, (variable, value) in env_values(model, env_prefix, other_prefixes=other_prefixes, owner=label).items():
        values[name] = value
        sources[name] = f"env {variable}"
    for name, value in (overrides or {}).items():
        values[name] = value
        sources[name] = override_origin
    try:
        config = model.model_validate(values)
    except ValidationError as exc:
        raise ConfigError(
            f"invalid config for method {label!r} (preset {preset!r}): {describe_errors(exc, sources)}"
        ) from None
    textual = {name for name, origin in sources.items() if origin.startswith("env ")}
    typed = set(overrides or {}) if typed_overrides else set()
    textual |= set(overrides or {}) - typed
    for name in sorted((textual | typed) & set(model.model_fields)):
        problem = _as_written(values[name], getattr(config, name), text=name in textual)
        if problem:
            raise ConfigError(
                f"invalid config for method {label!r} (preset {preset!r}): {name}: {problem} (from {sources[name]})"
            )
    _say_environment(label, sources, config)
    return ResolvedConfig(config, {name: sources[name] for name in model.model_fields})


def _say_environment(label: str, sources: Mapping[str, str], config: BaseModel) -> None:
    """One line per value an ``ALBOT1_<METHOD>_<FIELD>`` variable set, once per process.

    Why: a variable exported in a shell long ago changes every run of the
    method without a word on the command line; the run's config and key
    record it, but a user comparing with earlier results must be told.
    """
    for name, origin in sources.items():
        if not origin.startswith("env "):
            continue
        value = repr(getattr(config, name))
        if (label, origin, value) not in _said:
            _said.add((label, origin, value))
            log.warning("%s: %s = %s from the environment (%s)", label, name, value, origin.removeprefix("env "))


def _as_written(given: Any, got: Any, *, text: bool) -> str:
    """Why the value ``given`` for a field must not become ``got``, or "" when it may.

    Only scalar fields are checked (a number or a boolean as validated); ``text``: ``given`` is user text
    (``--set``, an environment variable), which pydantic must convert, else a typed value (TOML).
    """
    if not isinstance(got, bool | int | float):
        return ""
    if text:
        if isinstance(given, str) and not isinstance(got, bool) and not is_number(given):
            return f"found {given[:40]!r}, expected a number in ASCII digits without '_' grouping (e.g. 10 or 0.5)"
        return ""
    if isinstance(got, bool):
        ok = isinstance(given, bool)
        expected = "a boolean (true or false)"
    elif isinstance(got, int):
        ok = isinstance(given, int) and not isinstance(given, bool)
        expected = "an integer"
    else:
        ok = isinstance(given, int | float) and not isinstance(given, bool)
        expected = "a number"
    return "" if ok else f"found {_typed(given)}, expected {expected}"


def _typed(value: Any) -> str:
    """``the boolean true``, ``the string '2'``, ``the float 2.0``: a TOML value named with its type."""
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, str):
        return f"the string {value[:40]!r}"
    return f"the {type(value).__name__} {value!r}"
