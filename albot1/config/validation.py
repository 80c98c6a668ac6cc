"""One wording for pydantic validation errors: ``where: what`` per problem.

Every place that validates user input with pydantic (preset files, resolved
configs, benchmark suites) reports through :func:`describe_errors`, so a
user sees the same shape of message whatever file or flag they got wrong.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from pydantic import ValidationError


def describe_errors(exc: ValidationError, sources: Mapping[str, str] | None = None, *, found: bool = False) -> str:
    """``"a.b: Input should be ...; c: Extra inputs are not permitted"``.

    ``sources`` maps a top-level field name to where its value came from
    (e.g. an environment variable); when given, the problem says so, so a bad
    value is traced to the flag, variable or file line that set it.

    ``found``: a value of the wrong type also says what it was (``memory_mb: Input should be a valid number,
    found the boolean true``): under strict validation "a valid number" alone does not tell a user that the
    ``true`` or ``"5"`` they wrote is the problem.
    """
    problems = []
    errors = exc.errors()
    for error in errors:
        if error["type"] == "too_short" and _an_item_failed(error["loc"], errors):
            # pydantic counts a list's items after dropping the ones that failed: "methods: at least 1 item" beside
            # "methods.0.presett: ..." blames a list that has its entry (the entry's own error says what is wrong)
            continue
        location = ".".join(str(part) for part in error["loc"]) or "(top level)"
        if error["loc"]:
            origin = sources.get(str(error["loc"][0])) if sources else None
            suffix = f" (from {origin})" if origin else ""
        else:
            suffix = _named_origins(error["msg"], sources or {})
        problems.append(f"{location}: {error['msg']}{_found(error, typed=found)}{suffix}")
    return "; ".join(problems)


def _named_origins(message: str, sources: Mapping[str, str]) -> str:
    """``" (exit_min_width_m from --set)"``: where the fields a cross-field (top level) error names came from,
    so that a rule between two fields is traced to the flag or variable that broke it."""
    named = [
        f"{name} from {origin}" for name, origin in sources.items() if re.search(rf"\b{re.escape(name)}\b", message)
    ]
    return f" ({'; '.join(named)})" if named else ""


#: Error kinds whose input is not the problem: a missing field has none, an unknown field's value is beside the point.
_NO_VALUE_SHOWN = frozenset({"missing", "extra_forbidden"})
#: A string shown bare (``found 0``, ``found inf``): what a person types for one value; anything else is quoted.
_BARE = re.compile(r"[\w.+\-]{1,40}")
#: A quoted string is cut to this many characters, so one bad value cannot flood the line.
_SHOWN_CHARS = 60


def _found(error: Any, *, typed: bool = False) -> str:
    """``", found 0"``: the value that was rejected, when it is one number, boolean or string.

    Why: "Input should be greater than or equal to 1" says what was expected;
    the value found tells a user which of their inputs it was (a ``--set``, an
    environment variable and a preset may all set the same field).
    Containers (a whole table, a list) are not repeated: their own items'
    errors name them. ``typed`` (:func:`describe_errors`' ``found``): a value
    of the wrong type is named with its type (``found the boolean true``).
    """
    if error["type"] in _NO_VALUE_SHOWN or "input" not in error or "found " in error["msg"]:
        return ""  # (a validator of this project's own says what it found in its message: not twice)
    value = error["input"]
    if typed and _is_type_error(error["type"]):
        return f", found {_describe_value(value)}"
    if isinstance(value, str):
        if _BARE.fullmatch(value):
            return f", found {value}"
        shown = value if len(value) <= _SHOWN_CHARS else value[:_SHOWN_CHARS] + "..."
        return f", found {shown!r}"
    if value is None or isinstance(value, bool):
        return f", found {str(value).lower() if isinstance(value, bool) else 'null'}"  # as TOML and JSON spell them
    if isinstance(value, int | float):
        return f", found {value}"
    return ""


def _an_item_failed(loc: tuple[int | str, ...], errors: list[Any]) -> bool:
    """Whether some other error lies inside an item of the list at ``loc``."""
    return any(len(e["loc"]) > len(loc) and tuple(e["loc"][: len(loc)]) == tuple(loc) for e in errors)


def _is_type_error(kind: str) -> bool:
    """Whether a pydantic error type says the value had the wrong type (not a wrong value of the right one)."""
    return kind.endswith(("_type", "_parsing")) or kind == "literal_error"


def _describe_value(value: Any) -> str:
    """A value as its source file wrote it, in a few words: ``the boolean true``, ``the string '5'``, ``a list``."""
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, int):
        return f"the integer {value}"
    if isinstance(value, float):
        return f"the number {value!r}"
    if isinstance(value, str):
        return f"the string {value[:40]!r}{'...' if len(value) > 40 else ''}"
    if isinstance(value, list | tuple):
        return f"a list of {len(value)} item{'' if len(value) == 1 else 's'}"
    if isinstance(value, Mapping):
        return f"a table (keys {', '.join(map(str, list(value)[:5]))}{', ...' if len(value) > 5 else ''})"
    return f"a {type(value).__name__}"
