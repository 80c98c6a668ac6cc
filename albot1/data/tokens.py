"""Turning text fields into numbers: whitespace-separated fields of the
line-oriented parsers (errors name the offending token), and the values of
dataset reference options (``NAME?key=value``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.data.errors import ParseError


def parse_floats(path: str | Path, line: int, tokens: list[str], what: str, expected: str = "") -> NDArray[np.float64]:
    """``tokens`` as float64; else ParseError ``path:line: <what> 'tok' is not a number[; expected ...]``."""
    try:
        if not all(map(_plain, tokens)):
            raise ValueError("digit grouping or non-ASCII digits")
        return np.array(list(map(float, tokens)), dtype=np.float64)
    except ValueError:
        bad = next(t for t in tokens if not is_number(t))
        suffix = f"; expected {expected}" if expected else ""
        raise ParseError(path, f"{what} {bad!r} is not a number{suffix}", line=line) from None


def _plain(token: str | bytes) -> bool:
    """Whether ``token`` has neither Python's digit grouping nor a non-ASCII character (see :func:`is_number`)."""
    if isinstance(token, str):
        return "_" not in token and token.isascii()
    return b"_" not in token and token.isascii()


def is_number(token: str | bytes) -> bool:
    """Whether ``token`` is a number as the logs write them: what ``float()`` reads, but neither Python's digit
    grouping (``3_05`` would be read as 305) nor non-ASCII digits (full-width ``１``, Arabic-Indic ``٣``), which
    ``float()`` also reads but numpy, whose bulk conversion the CARMEN parser uses, refuses. ``nan`` and ``inf``
    are numbers here; a caller that needs a finite value tests that itself."""
    if not _plain(token):
        return False
    try:
        float(token)
    except ValueError:
        return False
    return True


def parse_scalar(token: str) -> int | float | str:
    """``"80"`` -> 80, ``"0.5"`` -> 0.5, anything else (``"laser-pose"``) unchanged.

    A dataset reference option is passed to its loader as a keyword, so a
    number typed in the reference must arrive as a number; an int is tried
    first so counts stay ints.
    """
    for convert in (int, float):
        try:
            return convert(token)
        except ValueError:
            continue
    return token
