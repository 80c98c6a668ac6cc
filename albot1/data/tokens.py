"""Turning whitespace-separated text fields into numbers with errors that
name the offending token (shared by the line-oriented parsers)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.data.errors import ParseError


def parse_floats(path: str | Path, line: int, tokens: list[str], what: str, expected: str = "") -> NDArray[np.float64]:
    """``tokens`` as float64; else ParseError ``path:line: <what> 'tok' is not a number[; expected ...]``."""
    try:
        return np.array(list(map(float, tokens)), dtype=np.float64)
    except ValueError:
        bad = next(t for t in tokens if not _is_float(t))
        suffix = f"; expected {expected}" if expected else ""
        raise ParseError(path, f"{what} {bad!r} is not a number{suffix}", line=line) from None


def _is_float(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True
