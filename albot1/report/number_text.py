"""How a number reads in the report's tables: significant digits, and the one text of an aggregate over seeds.

Every table that aggregates over seeds (``metrics.md``/``.tex``, ``cost.md``/``.tex``, ``index.html``; the
cells of :func:`albot1.report.tables.cell_text`) writes its numbers with :func:`stats_text`, and the
results page and thesis verdicts their single numbers with :func:`fmt`, so a number reads the same
everywhere: :data:`SIGNIFICANT` significant digits, scientific notation below 1e-3 and from :data:`LARGE`.
"""

from __future__ import annotations

import math

SIGNIFICANT = 3


def decimals(value: float, significant: int = SIGNIFICANT) -> int | None:
    """Decimals that show ``value`` to ``significant`` digits; None: use scientific notation (below 1e-3)."""
    magnitude = abs(float(f"{value:.{significant - 1}e}"))  # as rounded: 9.9996 shows as 10.0, not 10.00
    if magnitude == 0:
        return significant - 1
    if magnitude < 1e-3:
        return None
    return max(0, significant - 1 - math.floor(math.log10(magnitude)))


#: From this magnitude on a number is shown in scientific notation whatever its decimals: a diverged run's
#: 1e308 m would otherwise fill a table cell with 309 digits.
LARGE = 1e6


def fmt(value: float, places: int | None) -> str:
    """``value`` with ``places`` decimals (None, or a magnitude of :data:`LARGE` or more: scientific)."""
    if places is None or abs(value) >= LARGE:
        return f"{value:.{SIGNIFICANT - 1}e}"
    return f"{value:.{places}f}"


def stats_text(mean: float, std: float, median: float, low: float, high: float, n: int) -> str:
    """``mean`` for one seed; ``mean ± std, median M (min–max)`` for several, all with the decimals of the mean.

    The one text of an aggregate over seeds (Markdown, LaTeX, HTML): the median is there because one bad
    seed moves the mean and the std but not the median.
    """
    places = decimals(mean)
    if n <= 1 or low == high:
        return fmt(mean, places)
    spread = f"{fmt(mean, places)} ± {fmt(std, places)}, median {fmt(median, places)}"
    return f"{spread} ({fmt(low, places)}–{fmt(high, places)})"


#: A cell over seeds 1, 2 and 10 as :func:`stats_text` writes it, for the legends (so they show the real format).
EXAMPLE = stats_text(13 / 3, math.sqrt(73 / 3), 2.0, 1.0, 10.0, 3)
#: What a number over several seeds is, said above every table (Markdown and HTML) with :data:`EXAMPLE`.
SEEDS_LEGEND = "mean ± sample std over the completed seeds, their median, then (min–max)"
