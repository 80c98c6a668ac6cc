"""The few SVG figures of ``docs/results.md``, drawn from the results record alone.

They are committed with the page, so they must be byte-stable: no date in
the SVG metadata and a fixed hash salt for matplotlib's element ids, so a
run with the same numbers rewrites the same bytes (and git sees no change).
Published values are drawn hatched and named "(published)" in the legend,
never in a measured method's colour.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any, Protocol

from albot1.report.plots import method_color, pyplot
from albot1.report.standard import STANDARD_LOGS


class BarRow(Protocol):
    """What a figure reads of a standard-table row (``albot1.report.results_page.StandardRow``)."""

    @property
    def log(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def method(self) -> str: ...
    @property
    def status(self) -> str: ...
    @property
    def translation_mean_m(self) -> float | None: ...
    @property
    def speed(self) -> float | None: ...


RELATIONS_SVG = "relation-metric.svg"
SPEED_SVG = "speed.svg"
VERDICTS_SVG = "thesis-verdicts.svg"
#: Published systems: grey outlines, each its own hatch (never a measured method's colour).
PUBLISHED_STYLES = (
    ("#333333", "///"),
    ("#777777", "\\\\\\"),
    ("#555555", "xxx"),
    ("#999999", "..."),
    ("#444444", "---"),
)
VERDICT_COLORS = {"holds": "#2ca02c", "does not hold": "#d62728", "not comparable": "#bbbbbb"}


def _save(fig: Any, path: Path) -> None:
    plt = pyplot()
    with plt.rc_context({"svg.hashsalt": "albot1-results", "svg.fonttype": "path"}):
        fig.savefig(path, format="svg", metadata={"Date": None}, bbox_inches="tight")
    plt.close(fig)


def _grouped_bars(
    standard: Sequence[BarRow], value: str, kinds: tuple[str, ...], ylabel: str, title: str, path: Path
) -> bool:
    """One group of bars per standard log, one bar per (kind, method) with a value; False when nothing to draw."""
    series: list[tuple[str, str, dict[str, float]]] = []
    for kind in kinds:
        for method in dict.fromkeys(r.method for r in standard if r.kind == kind):
            values = {
                r.log: float(getattr(r, value))
                for r in standard
                if r.kind == kind and r.method == method and r.status == "done" and getattr(r, value) is not None
            }
            if values and all(v > 0 for v in values.values()):
                series.append((kind, method, values))
    if not series:
        return False
    plt = pyplot()
    logs = list(STANDARD_LOGS)
    fig, ax = plt.subplots(figsize=(8.0, 3.6))
    width = 0.8 / len(series)
    published = 0
    for i, (kind, method, values) in enumerate(series):
        xs = [j + (i - (len(series) - 1) / 2) * width for j, log in enumerate(logs) if log in values]
        ys = [values[log] for log in logs if log in values]
        if kind == "published":
            edge, hatch = PUBLISHED_STYLES[published % len(PUBLISHED_STYLES)]
            published += 1
            ax.bar(xs, ys, width, label=f"{method} (published)", color="white", edgecolor=edge, hatch=hatch)
        else:
            ax.bar(xs, ys, width, label=method, color=method_color(method))
    ax.set_xticks(range(len(logs)), logs)
    ax.set_yscale("log")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(axis="y", which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    _save(fig, path)
    return True


def _verdicts(counts: dict[str, dict[str, int]], path: Path) -> bool:
    if not counts:
        return False
    plt = pyplot()
    labels = list(counts)
    fig, ax = plt.subplots(figsize=(6.0, 0.5 + 0.5 * len(labels)))
    left = [0] * len(labels)
    for word in VERDICT_COLORS:
        widths = [counts[label][word] for label in labels]
        ax.barh(labels, widths, left=left, color=VERDICT_COLORS[word], label=word)
        left = [a + b for a, b in zip(left, widths, strict=True)]
    ax.set_xlabel("verdicts (claim x dataset)")
    ax.invert_yaxis()
    ax.legend(fontsize=7, ncol=3, loc="lower center", bbox_to_anchor=(0.5, 1.0))
    _save(fig, path)
    return True


def draw_figures(standard: Sequence[BarRow], counts: dict[str, dict[str, int]], out: Path) -> dict[str, str]:
    """Draw what there are numbers for into ``out``; file name -> caption. Figures with none are removed.

    ``standard``: the standard table's rows; ``counts``: variant -> verdict word -> count.
    """
    drawn: dict[str, str] = {}
    relations = out / RELATIONS_SVG
    if _grouped_bars(
        standard,
        "translation_mean_m",
        ("measured", "published"),
        "translational relation error, mean (m)",
        "Relation metric on the five standard logs: measured (solid) and published (hatched)",
        relations,
    ):
        drawn[RELATIONS_SVG] = (
            "Translational relation error (mean, m, log scale) per standard log: each method measured here "
            "(solid) beside the published systems (hatched, labelled published)."
        )
    if _grouped_bars(
        standard,
        "speed",
        ("measured",),
        "log duration / wall time",
        "Cost: how many times faster than real time the whole log was processed (this machine)",
        out / SPEED_SVG,
    ):
        drawn[SPEED_SVG] = (
            "Cost: log duration divided by wall-clock time per standard log and method, on the machine named "
            "above (higher is cheaper; compare methods within one run)."
        )
    if _verdicts(counts, out / VERDICTS_SVG):
        drawn[VERDICTS_SVG] = "The thesis's claims: verdicts per Albot1 variant, counted over claims and datasets."
    for name in (RELATIONS_SVG, SPEED_SVG, VERDICTS_SVG):
        if name not in drawn:
            (out / name).unlink(missing_ok=True)
    return drawn
