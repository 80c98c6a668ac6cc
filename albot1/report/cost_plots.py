"""Cost figures: per-scan time along each sequence, and per-scan time per dataset and method.

Times are measured with the suite's parallelism on a possibly shared
machine: compare them within one report.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from albot1.report.collect import CellRecord
from albot1.report.plots import pyplot, representative, save

if TYPE_CHECKING:
    import pandas as pd

PER_SCAN_FILE = "per_scan_ns.npy"


#: The running median spans 1 % of the scans but at least this many, so it smooths even a short run.
MIN_MEDIAN_WINDOW = 9


def median_window(scans: int) -> int:
    """The running median's window: 1 % of ``scans``, at least :data:`MIN_MEDIAN_WINDOW`, at most ``scans``."""
    return max(1, min(scans, max(MIN_MEDIAN_WINDOW, scans // 100)))


def running_median(values: NDArray[np.float64], window: int) -> NDArray[np.float64]:
    """The median of each ``window`` values around every position (edges padded with the end values)."""
    if window <= 1:
        return values
    from numpy.lib.stride_tricks import sliding_window_view

    padded = np.pad(values, (window // 2, window - 1 - window // 2), mode="edge")
    return np.median(sliding_window_view(padded, window), axis=1)


def plot_scan_time(records: list[CellRecord], dataset: str, path: Path, colors: dict[str, str]) -> Path | None:
    """Per-scan processing time along the sequence (running median over 1 % of it), one line per method."""
    runs = representative(records)
    if not runs:
        return None
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(9, 4), layout="constrained")
    drawn = 0
    for label, rec in runs.items():
        ns_file = rec.run_dir / PER_SCAN_FILE
        if not ns_file.is_file() or (rec.result is not None and rec.result.timing.per_scan_reason is not None):
            continue  # no times, or a batch method's bookkeeping (not its cost)
        ms = np.load(ns_file).astype(float) / 1e6
        if not len(ms):
            continue
        scans = np.arange(len(ms))
        ax.plot(scans, ms, color=colors.get(label), lw=0.4, alpha=0.25)  # raw, faint behind its median
        ax.plot(scans, running_median(ms, median_window(len(ms))), color=colors.get(label), lw=1.6, label=label)
        drawn += 1
    if not drawn:
        pyplot().close(fig)
        return None
    ax.set_yscale("log")
    ax.set_xlabel("scan index")
    ax.set_ylabel("per-scan time (ms)")
    ax.set_title(
        f"{dataset}: per-scan processing time along the sequence\n(thick: running median over "
        f"max({MIN_MEDIAN_WINDOW} scans, 1 % of them); faint: every scan)",
        fontsize=9,
    )
    ax.grid(alpha=0.3, which="both", lw=0.5)
    fig.legend(loc="outside right upper", fontsize=8, frameon=False)
    return save(fig, path)


def plot_runtime(cost: pd.DataFrame, path: Path, colors: dict[str, str]) -> Path | None:
    """Grouped bars: median per-scan time per dataset and method (undegraded runs), whisker to the p95."""
    if cost.empty or "per_scan_ms_median_mean" not in cost:
        return None
    rows = cost[(cost["degradation"] == "none") & cost["per_scan_ms_median_mean"].notna()]
    if rows.empty:
        return None
    plt = pyplot()
    datasets = list(dict.fromkeys(rows["dataset"]))
    methods = list(dict.fromkeys(rows["method"]))
    width = 0.8 / len(methods)
    fig, ax = plt.subplots(
        figsize=(min(16.0, max(7.0, 0.12 * len(datasets) * len(methods))), 5.0), layout="constrained"
    )
    for i, method in enumerate(methods):
        sub = rows[rows["method"] == method].set_index("dataset")
        xs, med, p95 = [], [], []
        for j, dataset in enumerate(datasets):
            if dataset in sub.index:
                xs.append(j + (i - (len(methods) - 1) / 2) * width)
                med.append(float(sub.loc[dataset, "per_scan_ms_median_mean"]))
                p95.append(float(sub.loc[dataset, "per_scan_ms_p95_mean"]))
        upper = np.maximum(np.asarray(p95) - np.asarray(med), 0.0)
        ax.bar(xs, med, width, yerr=[np.zeros_like(upper), upper], capsize=2, color=colors.get(method), label=method)
    ax.set_xticks(range(len(datasets)), datasets, rotation=35, ha="right", fontsize=7)
    ax.set_yscale("log")
    ax.set_ylabel("per-scan time (ms): median, whisker to p95")
    ax.set_title("Runtime per scan on each dataset's own odometry", fontsize=9)
    ax.grid(alpha=0.3, axis="y", which="both", lw=0.5)
    fig.legend(loc="outside right upper", fontsize=8, frameon=False)
    return save(fig, path)
