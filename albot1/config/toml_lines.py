"""Where a key of a TOML file is written: the line a validation error points a user to.

``tomllib`` keeps no positions, so a problem found by a model (``datasets.1.colour: Extra inputs are not
permitted``) could only name the key path; in a suite of twenty dataset entries the user then counts
``[[datasets]]`` headers by hand. :func:`key_lines` reads the text once more, line by line, and records
where each table header and each ``key = value`` starts; :func:`line_of` maps an error's location to the
line of its longest recorded prefix (``grid.seeds.0`` -> the ``seeds = [...]`` line, ``methods.0.set.x``
inside an inline table -> the ``set = {...}`` line). It is a locator, not a parser: the file has already
been parsed by ``tomllib``, so anything it cannot place simply gets no line.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

#: A location as pydantic reports it: table and key names, and list indices.
Location = tuple[str | int, ...]

_ARRAY_HEADER = re.compile(r"\[\[\s*([^\]]+?)\s*\]\]")
_TABLE_HEADER = re.compile(r"\[\s*([^\]]+?)\s*\]")
_KEY_PART = r"""(?:[A-Za-z0-9_-]+|"[^"]*"|'[^']*')"""
_KEY_VALUE = re.compile(rf"({_KEY_PART}(?:\s*\.\s*{_KEY_PART})*)\s*=(.*)")
#: One-line strings and a trailing comment: their brackets do not open or close a value.
_STRINGS_AND_COMMENT = re.compile(r"\"(?:[^\"\\]|\\.)*\"|'[^']*'|#.*")


def _dotted(key: str) -> tuple[str, ...]:
    """``a."b.c".d`` -> ``("a", "b.c", "d")``."""
    parts = re.findall(r"\"([^\"]*)\"|'([^']*)'|([A-Za-z0-9_-]+)", key)
    return tuple(next(part for part in groups if part) if any(groups) else "" for groups in parts)


def _balance(value: str) -> int:
    """Brackets and braces the value leaves open at the end of its line (a multi-line array)."""
    bare = _STRINGS_AND_COMMENT.sub("", value)
    return bare.count("[") + bare.count("{") - bare.count("]") - bare.count("}")


def key_lines(text: str) -> dict[Location, int]:
    """Location -> 1-based line of every table header and key of ``text`` (a TOML file that parses).

    ``[[name]]`` headers are numbered in order (``("datasets", 0)``, ``("datasets", 1)``), as the parsed list
    is; lines inside a multi-line array or string are not read as keys.
    """
    lines: dict[Location, int] = {}
    table: Location = ()
    arrays: dict[Location, int] = {}
    depth = 0
    in_string: str | None = None
    for number, raw in enumerate(text.splitlines(), 1):
        if in_string is not None:
            if raw.count(in_string) % 2 == 1:
                in_string = None
            continue
        if depth > 0:
            depth = max(0, depth + _balance(raw))
            continue
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        if (header := _ARRAY_HEADER.match(stripped)) is not None:
            path = _dotted(header[1])
            index = arrays.get(path, 0)
            arrays[path] = index + 1
            table = (*path, index)
            lines.setdefault(table, number)
            continue
        if (header := _TABLE_HEADER.match(stripped)) is not None:
            table = _dotted(header[1])
            lines.setdefault(table, number)
            continue
        if (pair := _KEY_VALUE.match(stripped)) is not None:
            lines.setdefault((*table, *_dotted(pair[1])), number)
            value = pair[2].strip()
            quote = value[:3]
            if quote in ('"""', "'''") and value.count(quote) % 2 == 1:
                in_string = quote
            else:
                depth = max(0, _balance(value))
    return lines


def line_of(lines: dict[Location, int], location: Sequence[str | int]) -> int | None:
    """The line of ``location`` or of its longest prefix that :func:`key_lines` recorded (None: none)."""
    for end in range(len(location), 0, -1):
        found = lines.get(tuple(location[:end]))
        if found is not None:
            return found
    return None
