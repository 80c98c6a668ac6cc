"""The one ``KEY=VALUE`` parser: config overrides (``--set FIELD=VALUE``) and
dataset reference options (``NAME?key=value&key=value``).

Why one function: both are typed by users, and the same mistakes (a missing
``=``, an empty key, a key given twice) must get the same clear message
wherever they are made. Values stay strings here; whoever consumes them
converts them (pydantic for config fields, the data layer for loader
options), because only they know the expected type.
"""

from __future__ import annotations

from collections.abc import Iterable

from albot1.errors import ConfigError


class KeyValueError(ConfigError):
    """An item is not ``KEY=VALUE``, or a key is given twice."""


def parse_key_values(items: Iterable[str], *, what: str = "setting", key: str = "KEY") -> dict[str, str]:
    """``["a=1", " b = x "]`` -> ``{"a": "1", "b": "x"}``.

    The item is split at its first ``=`` (a value may contain ``=``); key and
    value are stripped of surrounding whitespace; the key must not be empty,
    the value may be. A key given twice is an error rather than "the last one
    wins": with two different values, which one a run used would be a guess.
    ``what`` and ``key`` only word the error, e.g. ``override 'x' is not of
    the form FIELD=VALUE``.

    Raises:
        KeyValueError: the only exception this function raises.
    """
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise KeyValueError(f"{what} {item!r} is not of the form {key}=VALUE")
        if name in out:
            raise KeyValueError(f"{what} {name!r} is given twice ({out[name]!r} and {value.strip()!r}); give it once")
        out[name] = value.strip()
    return out


def parse_query(query: str, *, what: str = "option", key: str = "KEY") -> dict[str, str]:
    """``"a=1&b=x"`` -> ``{"a": "1", "b": "x"}``; empty items (``a=1&&b=2``, a trailing ``&``) are ignored."""
    return parse_key_values((item for item in query.split("&") if item), what=what, key=key)
