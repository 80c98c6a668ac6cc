"""One memo of matplotlib's parsed math text for a whole process, instead of one per figure.

A log axis labels its ticks in math text (``$\\mathdefault{10^{-2}}$``), and
matplotlib parses each label with pyparsing and lays it out in Python (tens of
milliseconds a label). It memoises the result, but keyed by the parser object,
and every renderer makes its own parser: each figure, and each of its two
formats, parsed the same few labels again (a default report: ~780 parses of
a few dozen distinct labels, about 6 % of its drawing CPU,
docs/benchmarking.md, "The reports' math text parsed once").

:func:`share_parsed_math` keys that memo by the parser's output kind (raster
for the PNG, vector for the SVG) instead of by the parser object: a label is
parsed once per kind, size, resolution, font and math-text settings (the
``mathtext.*`` entries of ``rcParams``, which the parse reads: ``mathtext.default``
sets the font of plain letters), and every later figure reuses it. The parse is
a pure function of that key (the renderers only read its result), so every
figure keeps its bytes. Where this matplotlib lacks the
private names the memo relies on, nothing is changed and the figures are
drawn as before.
"""

from __future__ import annotations

import functools
from typing import Any

#: Distinct (kind, text, dpi, font, ...) parses kept: a report's tick labels need a few dozen.
MEMO_SIZE = 1024


def share_parsed_math() -> bool:
    """Make every math-text parser of this process share one memo; whether it is in place (idempotent)."""
    from matplotlib import rcParams
    from matplotlib.mathtext import MathTextParser

    current = MathTextParser.__dict__.get("_parse_cached")
    if getattr(current, "_albot1_shared", False):
        return True
    parse = getattr(current, "__wrapped__", None)  # the undecorated parse of functools.lru_cache
    if parse is None or not hasattr(MathTextParser("agg"), "_output_type"):
        return False
    parsers: dict[str, Any] = {}
    settings = tuple(sorted(name for name in rcParams if name.startswith("mathtext.")))

    @functools.lru_cache(MEMO_SIZE)
    def parse_once(output_type: str, values: tuple[Any, ...], *key: Any) -> Any:
        # one parser per output kind does the parsing, so the result cannot depend on which renderer asked;
        # ``values`` (the settings now in force, which the parse reads itself) only keys the memo
        return parse(parsers[output_type], *key)

    def shared(self: Any, *key: Any) -> Any:
        parsers.setdefault(self._output_type, self)
        return parse_once(self._output_type, tuple(rcParams[name] for name in settings), *key)

    shared._albot1_shared = True  # type: ignore[attr-defined]
    setattr(MathTextParser, "_parse_cached", shared)  # noqa: B010 (a private name the stubs do not declare)
    return True
