"""One wording for pydantic validation errors: ``where: what`` per problem.

Every place that validates user input with pydantic (preset files, resolved
configs, benchmark suites) reports through :func:`describe_errors`, so a
user sees the same shape of message whatever file or flag they got wrong.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pydantic import ValidationError


def describe_errors(exc: ValidationError, sources: Mapping[str, str] | None = None) -> str:
    """``"a.b: Input should be ...; c: Extra inputs are not permitted"``.

    ``sources`` maps a top-level field name to where its value came from
    (e.g. an environment variable); when given, the problem says so, so a bad
    value is traced to the flag, variable or file line that set it.
    """
    problems = []
    errors = exc.errors()
    for error in errors:
        if error["type"] == "too_short" and _an_item_failed(error["loc"], errors):
            # pydantic counts a list's items after dropping the ones that failed: "methods: at least 1 item" beside
            # "methods.0.presett: ..." blames a list that has its entry (the entry's own error says what is wrong)
            continue
        location = ".".join(str(part) for part in error["loc"]) or "(top level)"
        origin = sources.get(str(error["loc"][0])) if sources and error["loc"] else None
        suffix = f" (from {origin})" if origin else ""
        problems.append(f"{location}: {error['msg']}{suffix}")
    return "; ".join(problems)


def _an_item_failed(loc: tuple[int | str, ...], errors: list[Any]) -> bool:
    """Whether some other error lies inside an item of the list at ``loc``."""
    return any(len(e["loc"]) > len(loc) and tuple(e["loc"][: len(loc)]) == tuple(loc) for e in errors)
