""" "Did you mean" for every name a user types (methods, presets, datasets, option values).

One rule for all of them so that a typo reads the same everywhere: the
closest known names by :func:`difflib.get_close_matches`, compared without
case (``Thesis`` finds ``thesis``) and with ``_`` read as ``-`` (``kiss_icp``
finds ``kiss-icp``). A long list of known names is not printed on one
line: the message then names where to see them all.
"""

from __future__ import annotations

import difflib
from collections.abc import Sequence

#: Above this many known names a message suggests instead of listing them all.
LIST_AT_MOST = 10


def _folded(name: str) -> str:
    return name.casefold().replace("_", "-")


def closest(name: str, known: Sequence[str], n: int = 3) -> list[str]:
    """The known names closest to ``name``, best first (an exact match up to case and ``_``/``-`` first)."""
    by_fold: dict[str, str] = {}
    for item in known:
        by_fold.setdefault(_folded(item), item)
    exact = by_fold.get(_folded(name))
    matches = difflib.get_close_matches(_folded(name), list(by_fold), n=n, cutoff=0.6)
    out = [exact] if exact is not None else []
    out += [by_fold[m] for m in matches if by_fold[m] not in out]
    return out[:n]


def did_you_mean(name: str, known: Sequence[str]) -> str:
    """``" (did you mean 'x'?)"`` (or ``'x' or 'y'``), or ``""`` when nothing is close."""
    found = closest(name, known)
    if not found:
        return ""
    return " (did you mean " + " or ".join(repr(f) for f in found) + "?)"


def unknown_name_message(what: str, name: str, known: Sequence[str], listing: str | None = None) -> str:
    """One line: ``unknown WHAT 'NAME'; did you mean ...?`` then the known names, or where to list them.

    ``listing`` is the command that lists every name; it is named instead of
    the names when there are more than :data:`LIST_AT_MOST` of them.
    """
    message = f"unknown {what} {name!r}" + did_you_mean(name, known)
    if len(known) <= LIST_AT_MOST or listing is None:
        return f"{message}; expected one of: {', '.join(known)}"
    return f"{message}; `{listing}` lists all {len(known)}"
