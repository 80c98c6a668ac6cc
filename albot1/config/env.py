"""Config values from environment variables ``ALBOT1_<METHOD>_<FIELD>``, unknown names rejected.

Why reject: a variable that names no field (``ALBOT1_KISS_ICP_VOXEL_SIZE``
for the field ``voxel_size_m``) used to be silently ignored, so a run went
ahead with a value its user believed they had changed. Every variable under
a method's prefix must now name one of its fields.

Prefixes can nest: method ``albot1`` reads ``ALBOT1_ALBOT1_*`` and a method
``albot1-places`` would read ``ALBOT1_ALBOT1_PLACES_*``. A variable belongs
to the method with the *longest* prefix it starts with, so
``ALBOT1_ALBOT1_PLACES_X`` is never judged as an ``albot1`` field while
``albot1-places`` is registered. The project's own settings
(``ALBOT1_DATA_DIR``, ``ALBOT1_CACHE_DIR``, ``ALBOT1_CONFIG_DIR``) are never
method variables.

Reading is done by pydantic-settings' :class:`EnvSettingsSource` on a
settings class mirroring the config model's fields (names matched without
regard to case, as pydantic-settings does by default); the values are
returned raw, and validated with everything else by the config model.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from functools import cache
from typing import Any

from pydantic import BaseModel, create_model
from pydantic_settings import BaseSettings, EnvSettingsSource, SettingsConfigDict
from pydantic_settings.exceptions import SettingsError

from albot1.errors import ConfigError
from albot1.resources import CONFIG_DIR_ENV
from albot1.settings import CACHE_DIR_ENV, DATA_DIR_ENV

#: The project's settings: they start with ``ALBOT1_`` but never configure a method.
SETTINGS_VARIABLES = frozenset({DATA_DIR_ENV, CACHE_DIR_ENV, CONFIG_DIR_ENV})
#: Every other ``ALBOT1_`` variable the project reads (defined beside their readers, which this layer must not
#: import: the decoded-log cache, numba's compile processes, the bench's preload and Dask wait, the wheel build,
#: the scaling benchmark); ``tests/unit/config/test_config_env.py`` checks the list against the sources.
OTHER_SETTINGS = frozenset(
    {
        "ALBOT1_DECODED_CACHE",
        "ALBOT1_COMPILE_PROCESSES",
        "ALBOT1_PRELOAD_METHODS",
        "ALBOT1_DASK_CONNECT_TIMEOUT",
        "ALBOT1_BUILD_COMMIT",
        "ALBOT1_BUILD_KERNELS",
        "ALBOT1_SCALING_CELLS",
    }
)

ENV_ROOT = "ALBOT1_"


class UnknownEnvironmentVariableError(ConfigError):
    """A variable under a method's prefix names none of its config fields."""


def method_prefix(method: str) -> str:
    """``"kiss-icp"`` -> ``"ALBOT1_KISS_ICP_"`` (upper case, dashes as underscores)."""
    return ENV_ROOT + method.upper().replace("-", "_") + "_"


def owner_of(variable: str, prefixes: Iterable[str]) -> str | None:
    """The longest of ``prefixes`` that ``variable`` starts with (case-insensitive), or None."""
    name = variable.upper()
    matching = [p for p in prefixes if name.startswith(p.upper())]
    return max(matching, key=len) if matching else None


class _Environment(BaseSettings):
    """Base of the per-model settings classes: only read, never instantiated."""

    model_config = SettingsConfigDict(case_sensitive=False, extra="ignore")


@cache
def _settings_class(model: type[BaseModel]) -> type[BaseSettings]:
    """A settings class with ``model``'s field names and types (so complex types are JSON-decoded)."""
    fields: dict[str, Any] = {name: (info.annotation, None) for name, info in model.model_fields.items()}
    return create_model(f"{model.__name__}Environment", __base__=_Environment, **fields)


def env_values(
    model: type[BaseModel], prefix: str, *, other_prefixes: Iterable[str] = (), owner: str = ""
) -> dict[str, tuple[str, Any]]:
    """``{field: (VARIABLE, raw value)}`` for every ``prefix + FIELD`` variable that is set.

    ``other_prefixes`` are the prefixes of the other registered methods: a
    variable that a longer one of them claims is left to that method.
    ``owner`` names the method in messages.

    Raises:
        UnknownEnvironmentVariableError: a variable this prefix owns names no
            field; the message names it, suggests the closest field and lists
            every valid name.
        ConfigError: a value pydantic-settings cannot decode (a complex field's JSON).
    """
    prefixes = [prefix, *other_prefixes]
    try:
        source = EnvSettingsSource(_settings_class(model), env_prefix=prefix, case_sensitive=False)
        raw: dict[str, Any] = source()
    except SettingsError as exc:
        raise ConfigError(f"{owner or prefix}: an environment variable cannot be read: {exc}") from None
    fields = list(model.model_fields)
    valid = [prefix + name.upper() for name in fields]
    for variable in sorted(source.env_vars):
        upper = variable.upper()
        if upper in SETTINGS_VARIABLES or owner_of(upper, prefixes) != prefix:
            continue
        if upper[len(prefix) :].lower() not in model.model_fields:
            close = difflib.get_close_matches(upper, valid, n=1)
            hint = f"did you mean {close[0]}? " if close else ""
            raise UnknownEnvironmentVariableError(
                f"environment variable {upper} names no config field of {owner or model.__name__}; "
                f"{hint}valid names: {', '.join(valid)}"
            )
    return {name: (prefix + name.upper(), value) for name, value in raw.items()}


def stray_variables(environ: Iterable[str], prefixes: Iterable[str], valid: Iterable[str]) -> list[tuple[str, str]]:
    """``(variable, message)`` per ``ALBOT1_`` variable in ``environ`` that no method prefix owns nor setting names.

    Why: ``ALBOT1_KISSICP_VOXEL_SIZE_M`` (the method's name misspelt) belongs
    to no method, so the per-method check never sees it and the run silently
    keeps the preset's value. ``valid``: every method variable, for the hint.
    """
    known = SETTINGS_VARIABLES | OTHER_SETTINGS
    owned = list(prefixes)
    candidates = sorted(set(valid) | known)
    messages = []
    for variable in sorted(environ):
        upper = variable.upper()
        if not upper.startswith(ENV_ROOT) or upper in known or owner_of(upper, owned) is not None:
            continue
        close = difflib.get_close_matches(upper, candidates, n=1)
        hint = f"; did you mean {close[0]}?" if close else ""
        messages.append(
            (
                variable,
                f"environment variable {variable} names no registered method's field nor a setting of "
                f"albot1-bench (ignored){hint}",
            )
        )
    return messages
