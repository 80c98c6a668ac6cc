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
    """``value`` with ``places`` decimals (None, or a magnitude of :data:`LARGE` or more: scientific).

    A number that rounds to zero reads without a sign: ``-0.001`` at two decimals is ``0.00``, not ``-0.00``
    (a negative number where the table has none).
    """
    if places is None or abs(value) >= LARGE:
        text = f"{value:.{SIGNIFICANT - 1}e}"
    else:
        text = f"{value:.{places}f}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text


def stats_text(mean: float, std: float, median: float, low: float, high: float, n: int) -> str:
    """``mean`` for one seed; ``mean ± std, median M (min–max)`` for several, all with the decimals of the mean.

    The one text of an aggregate over seeds (Markdown, LaTeX, HTML): the median is there because one bad
    seed moves the mean and the std but not the median. A std that would read zero at the mean's decimals
    while the seeds differ (``1234 ± 0`` for seeds 0.6 m apart) is shown to its own first significant digit:
    ``± 0`` is what seeds that agree would give, and those read as one number.
    """
    places = decimals(mean)
    if n <= 1 or low == high:
        return fmt(mean, places)
    deviation = fmt(std, places)
    if std > 0 and float(deviation) == 0:
        deviation = fmt(std, decimals(std, 1))
    spread = f"{fmt(mean, places)} ± {deviation}, median {fmt(median, places)}"
    return f"{spread} ({fmt(low, places)}–{fmt(high, places)})"


#: A cell over seeds 1, 2 and 10 as :func:`stats_text` writes it, for the legends (so they show the real format).
EXAMPLE = stats_text(13 / 3, math.sqrt(73 / 3), 2.0, 1.0, 10.0, 3)
#: What a number over several seeds is, said above every table (Markdown and HTML) with :data:`EXAMPLE`.
SEEDS_LEGEND = "mean ± sample std over the completed seeds, their median, then (min–max)"
