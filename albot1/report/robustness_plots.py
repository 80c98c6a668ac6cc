"""Robustness: a metric per odometry degradation (or other perturbation), per method, across seeds.

Degradations are categories (``none``, Gaussian levels by sigma, biases,
``thesis``, then a wrong laser offset and scan dropout), not points on a numeric axis, so each is a slot on the x axis
and no line joins unrelated settings. Each method is a marker at the mean
over seeds with a bar of +/- one sample standard deviation and small ticks
at the minimum and maximum; a deterministic degradation has one seed and
no bar. A log axis is used only when the values span more than two
decades, starting at 1e-4 of the largest value: a perfect-odometry error of
1e-10 m is drawn at that floor with a downward triangle (and said so)
instead of stretching the axis over ten empty decades.

The axis names what its levels change: "odometry degradation" only when
every level is one (``gauss``, ``bias``, ``thesis``); a suite that also
sweeps ``offset`` or ``dropout`` (the generalisation suite) gets
"perturbation" with the kinds it holds, since a dropout leaves the odometry
as it is and thins the scans.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from albot1.data.degrade import parse_spec
from albot1.report.collect import severity_order
from albot1.report.plots import log_floor, pyplot, save, value_axis

if TYPE_CHECKING:
    import pandas as pd


def plot_robustness(
    table: pd.DataFrame, dataset: str, column: str, label: str, path: Path, colors: dict[str, str]
) -> Path | None:
    """``column`` (an aggregated metric) per degradation and method; None when there is nothing to compare."""
    rows = table[(table["dataset"] == dataset) & table[f"{column}_mean"].notna()]
    if rows.empty or rows["degradation"].nunique() < 2:
        return None
    plt = pyplot()
    levels = severity_order(list(dict.fromkeys(rows["degradation"])))
    methods = list(dict.fromkeys(rows["method"]))
    slot = 0.8 / len(methods)
    floor = log_floor([rows[f"{column}_mean"].to_numpy(float), rows[f"{column}_max"].to_numpy(float)])
    fig, ax = plt.subplots(figsize=(max(6.5, 1.3 * len(levels) + 0.25 * len(methods)), 4.4), layout="constrained")
    clipped: list[str] = []
    for i, method in enumerate(methods):
        color = colors.get(method, "C0")
        group = rows[rows["method"] == method]
        for _, row in group.iterrows():
            x = levels.index(row["degradation"]) + (i - (len(methods) - 1) / 2) * slot
            mean = float(row[f"{column}_mean"])
            std = float(row[f"{column}_std"])
            low, high = float(row[f"{column}_min"]), float(row[f"{column}_max"])
            if floor is not None and mean < floor:
                clipped.append(method)
                ax.plot([x], [floor], marker="v", ms=6, color=color, ls="none")
                continue
            if not math.isnan(std) and std > 0:
                bottom = mean - std if floor is None else max(mean - std, floor)
                ax.plot([x, x], [bottom, mean + std], color=color, lw=2.2, alpha=0.55, solid_capstyle="butt")
            if high > low:
                ax.plot([x, x], [max(low, floor or low), high], color=color, lw=0.6, alpha=0.8)
                ax.plot([x - slot * 0.25, x + slot * 0.25], [high, high], color=color, lw=0.8)
                if floor is None or low >= floor:
                    ax.plot([x - slot * 0.25, x + slot * 0.25], [low, low], color=color, lw=0.8)
            ax.plot([x], [mean], marker="o", ms=5, color=color, ls="none")
        ax.plot([], [], marker="o", ms=5, color=color, ls="none", label=method)
    value_axis(ax, floor, sorted(set(clipped)), "")
    ax.set_xticks(range(len(levels)), levels, fontsize=8)
    for k in range(1, len(levels)):
        ax.axvline(k - 0.5, color="0.85", lw=0.8, zorder=0)
    ax.set_xlim(-0.5, len(levels) - 0.5)
    what, axis = axis_words(levels)
    ax.set_xlabel(axis, fontsize=8)
    ax.set_ylabel(label)
    ax.grid(alpha=0.3, axis="y", which="both", lw=0.5)
    seeds = int(rows["seeds"].max())
    fig.suptitle(f"{dataset}: {label} per {what}", fontsize=10)
    ax.set_title(
        f"marker: mean over the seeds (up to {seeds}); thick bar: ± 1 sample std; ticks: min and max",
        fontsize=8,
        color="0.3",
    )
    fig.legend(loc="outside lower center", ncols=min(len(methods), 6), fontsize=8, frameon=False)
    return save(fig, path)


#: What each kind of level changes, in the axis label's words (``albot1/data/degrade.py``).
_CHANGES = {
    "gauss": "odometry noise",
    "bias": "odometry bias",
    "thesis": "the thesis's odometry error",
    "offset": "a wrong laser offset",
    "dropout": "scan dropout",
}


def axis_words(levels: list[str]) -> tuple[str, str]:
    """(what a level is, the x axis label) for these levels: an odometry degradation unless one is not.

    ``offset`` reports the odometry of a displaced frame and ``dropout`` leaves scans out (their odometry
    untouched): a figure with them was labelled "odometry degradation (applied to the dataset's odometry
    ...)" all the same.
    """
    kinds = [parse_spec(level, stored=True).kind for level in levels]
    if all(kind in ("none", "gauss", "bias", "thesis") for kind in kinds):
        return (
            "odometry degradation",
            "odometry degradation (applied to the dataset's odometry before any method sees it)",
        )
    held = ", ".join(dict.fromkeys(_CHANGES[kind] for kind in kinds if kind in _CHANGES))
    return "perturbation", f"perturbation ({held}; applied to the data before any method sees it)"
