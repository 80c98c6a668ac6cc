"""Turning text fields into numbers: whitespace-separated fields of the
line-oriented parsers (errors name the offending token), and the values of
dataset reference options (``NAME?key=value``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.config.numbers import is_number, is_plain
from albot1.data.errors import ParseError

__all__ = ["is_number", "parse_floats", "parse_scalar"]


def parse_floats(path: str | Path, line: int, tokens: list[str], what: str, expected: str = "") -> NDArray[np.float64]:
    """``tokens`` as float64; else ParseError ``path:line: <what> 'tok' is not a number[; expected ...]``."""
    try:
        if not all(map(is_plain, tokens)):
            raise ValueError("digit grouping or non-ASCII digits")
        return np.array(list(map(float, tokens)), dtype=np.float64)
    except ValueError:
        bad = next(t for t in tokens if not is_number(t))
        suffix = f"; expected {expected}" if expected else ""
        raise ParseError(path, f"{what} {bad!r} is not a number{suffix}", line=line) from None


def parse_scalar(token: str) -> int | float | str:
    """``"80"`` -> 80, ``"0.5"`` -> 0.5, anything else (``"laser-pose"``) unchanged.

    A dataset reference option is passed to its loader as a keyword, so a
    number typed in the reference must arrive as a number; an int is tried
    first so counts stay ints. Only :func:`is_number` text is a number (``1_0`` and ``１０`` stay strings, which
    the loader then refuses by name, rather than silently becoming 10).
    """
    if not is_number(token):
        return token
    for convert in (int, float):
        try:
            return convert(token)
        except ValueError:
            continue
    return token
