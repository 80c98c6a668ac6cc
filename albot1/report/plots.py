"""Report plots, rendered headless (Agg): maps, trajectory overlays, robustness curves, cost.

For every dataset the *representative run* of a method is its run on the
dataset's own odometry (degradation ``none``) with the lowest seed, falling
back to the first completed cell; maps and overlays show that run so every
method is pictured on the same input. Estimates are drawn after the rigid
alignment the ATE uses (:func:`albot1.metrics.alignment.align`), so the
picture and the number agree; without reference poses each method is drawn
in its own frame.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from albot1.geometry import se2
from albot1.metrics.alignment import align, rigid_transform
from albot1.report.collect import CellRecord, severity_order

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes

MAX_MAP_POINTS = 60_000
COLORS = ("tab:blue", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan")


def slug(text: str) -> str:
    """A file-name-safe version of a dataset or method label."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "x"


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def representative(records: Iterable[CellRecord]) -> dict[str, CellRecord]:
    """method label -> its representative completed run (see module doc)."""
    best: dict[str, CellRecord] = {}
    for rec in records:
        if rec.status != "done":
            continue
        c = rec.cell
        current = best.get(c.method_label)
        rank = (c.degradation != "none", c.seed)
        if current is None or rank < (current.cell.degradation != "none", current.cell.seed):
            best[c.method_label] = rec
    return best


def _aligned_xy(poses: np.ndarray, reference: np.ndarray | None) -> np.ndarray:
    if reference is None or len(reference) != len(poses) or len(poses) < 2:
        return poses[:, :2]
    try:
        aligned, _ = align(poses, reference, "rigid")
    except Exception:  # noqa: BLE001 -- a picture is still useful unaligned; the metrics say why
        return poses[:, :2]
    return np.asarray(aligned)[:, :2]


def _transform_points(points: np.ndarray, poses: np.ndarray, reference: np.ndarray | None) -> np.ndarray:
    """Apply to map points the same rigid motion that aligns ``poses`` onto ``reference``."""
    if reference is None or len(reference) != len(poses) or len(poses) < 2 or not len(points):
        return points
    try:
        transform = rigid_transform(poses, reference)
    except Exception:  # noqa: BLE001 -- see _aligned_xy
        return points
    return se2.transform_points(transform, points)


def _draw_run(ax: Axes, rec: CellRecord, color: str) -> None:
    from matplotlib.collections import LineCollection

    run = rec.stored_run()
    ref = run.reference
    data = run.load_map()
    if data.points is not None and len(data.points):
        pts = np.asarray(data.points, dtype=float)
        if len(pts) > MAX_MAP_POINTS:
            pts = pts[np.random.default_rng(0).choice(len(pts), MAX_MAP_POINTS, replace=False)]
        pts = _transform_points(pts, run.poses, ref)
        ax.scatter(pts[:, 0], pts[:, 1], s=0.15, c="0.45", linewidths=0, rasterized=True)
    if data.segments is not None and len(data.segments):
        ends = np.asarray(data.segments, dtype=float).reshape(-1, 2)
        seg = _transform_points(ends, run.poses, ref).reshape(-1, 2, 2)
        ax.add_collection(LineCollection(list(seg), colors="0.2", linewidths=0.7))
    if ref is not None:
        ax.plot(ref[:, 0], ref[:, 1], color="tab:orange", lw=0.8, label="reference")
    xy = _aligned_xy(run.poses, ref)
    ax.plot(xy[:, 0], xy[:, 1], color=color, lw=0.8, label="estimate")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.tick_params(labelsize=6)


def plot_maps(records: list[CellRecord], dataset: str, path: Path) -> Path | None:
    """One panel per method: its map and trajectory, with the reference."""
    runs = representative(records)
    if not runs:
        return None
    plt = _pyplot()
    n = len(runs)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 4.2 * rows), dpi=110, squeeze=False)
    for ax, (i, (label, rec)) in zip(axes.flat, enumerate(runs.items())):
        _draw_run(ax, rec, COLORS[i % len(COLORS)])
        ax.set_title(f"{label} [{rec.cell.degradation}, seed {rec.cell.seed}]", fontsize=8)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    axes.flat[0].legend(loc="best", fontsize=6)
    fig.suptitle(f"{dataset}: maps and trajectories", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, format="png")
    plt.close(fig)
    return path


def plot_trajectories(records: list[CellRecord], dataset: str, path: Path) -> Path | None:
    """Every method's trajectory over the reference (aligned as for the ATE)."""
    runs = representative(records)
    if not runs:
        return None
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 7), dpi=110)
    reference_drawn = False
    for i, (label, rec) in enumerate(runs.items()):
        run = rec.stored_run()
        if run.reference is not None and not reference_drawn:
            ax.plot(run.reference[:, 0], run.reference[:, 1], color="black", lw=1.4, alpha=0.5, label="reference")
            reference_drawn = True
        xy = _aligned_xy(run.poses, run.reference)
        ax.plot(xy[:, 0], xy[:, 1], color=COLORS[i % len(COLORS)], lw=0.9, label=label)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    aligned = "rigidly aligned to the reference" if reference_drawn else "each in its own frame (no reference)"
    ax.set_title(f"{dataset}: trajectories, {aligned}", fontsize=9)
    ax.legend(loc="best", fontsize=7)
    fig.savefig(path, format="png", bbox_inches="tight")
    plt.close(fig)
    return path


def plot_robustness(table: pd.DataFrame, dataset: str, column: str, label: str, path: Path) -> Path | None:
    """Error versus degradation level per method (mean with min–max bars over seeds)."""
    rows = table[table["dataset"] == dataset]
    if rows.empty or rows["degradation"].nunique() < 2 or rows[f"{column}_mean"].notna().sum() < 2:
        return None
    plt = _pyplot()
    levels = severity_order(list(dict.fromkeys(rows["degradation"])))
    x_of = {level: i for i, level in enumerate(levels)}
    fig, ax = plt.subplots(figsize=(7, 4.2), dpi=110)
    for i, (method, group) in enumerate(rows.groupby("method", sort=False)):
        group = group[group[f"{column}_mean"].notna()]
        if group.empty:
            continue
        group = group.iloc[np.argsort([x_of[d] for d in group["degradation"]], kind="stable")]
        xs = np.array([x_of[d] for d in group["degradation"]], dtype=float) + (i - 2) * 0.04
        mean = group[f"{column}_mean"].to_numpy(float)
        # mean - min can come out as -1e-17 when every seed agrees: clip the rounding away
        low = np.maximum(mean - group[f"{column}_min"].to_numpy(float), 0.0)
        high = np.maximum(group[f"{column}_max"].to_numpy(float) - mean, 0.0)
        ax.errorbar(
            xs, mean, yerr=[low, high], marker="o", ms=4, capsize=3, lw=1, color=COLORS[i % len(COLORS)], label=method
        )
    ax.set_xticks(range(len(levels)), levels, rotation=20, fontsize=8)
    if (rows[f"{column}_min"].dropna() > 0).all():
        ax.set_yscale("log")
    ax.set_xlabel("odometry degradation (SPEC)")
    ax.set_ylabel(label)
    ax.set_title(f"{dataset}: {label} vs odometry degradation (mean, min–max over seeds)", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.savefig(path, format="png", bbox_inches="tight")
    plt.close(fig)
    return path


def plot_scan_time(records: list[CellRecord], dataset: str, path: Path) -> Path | None:
    """Per-scan processing time along the sequence (running median), one line per method."""
    runs = representative(records)
    if not runs:
        return None
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4), dpi=110)
    for i, (label, rec) in enumerate(runs.items()):
        ns_file = rec.run_dir / "per_scan_ns.npy"
        if not ns_file.is_file():
            continue
        ms = np.load(ns_file).astype(float) / 1e6
        if not len(ms):
            continue
        window = max(1, len(ms) // 100)
        smooth = _running_median(ms, window)
        ax.plot(np.arange(len(ms)), smooth, color=COLORS[i % len(COLORS)], lw=0.9, label=label)
    ax.set_yscale("log")
    ax.set_xlabel("scan index")
    ax.set_ylabel("per-scan time (ms), running median")
    ax.set_title(f"{dataset}: per-scan processing time along the sequence", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.savefig(path, format="png", bbox_inches="tight")
    plt.close(fig)
    return path


def _running_median(values: np.ndarray, window: int) -> np.ndarray:
    if window <= 1:
        return values
    from numpy.lib.stride_tricks import sliding_window_view

    padded = np.pad(values, (window // 2, window - 1 - window // 2), mode="edge")
    return np.median(sliding_window_view(padded, window), axis=1)


def plot_runtime(cost: pd.DataFrame, path: Path) -> Path | None:
    """Grouped bars: median per-scan time per dataset and method (undegraded runs), p95 as whisker."""
    rows = cost[(cost["degradation"] == "none") & cost["per_scan_ms_median_mean"].notna()]
    if rows.empty:
        return None
    plt = _pyplot()
    datasets = list(dict.fromkeys(rows["dataset"]))
    methods = list(dict.fromkeys(rows["method"]))
    width = 0.8 / len(methods)
    fig, ax = plt.subplots(figsize=(min(16.0, max(7.0, 0.12 * len(datasets) * len(methods))), 4.5), dpi=110)
    for i, method in enumerate(methods):
        sub = rows[rows["method"] == method].set_index("dataset")
        xs, med, p95 = [], [], []
        for j, dataset in enumerate(datasets):
            if dataset in sub.index:
                xs.append(j + (i - (len(methods) - 1) / 2) * width)
                med.append(float(sub.loc[dataset, "per_scan_ms_median_mean"]))
                p95.append(float(sub.loc[dataset, "per_scan_ms_p95_mean"]))
        upper = np.maximum(np.asarray(p95) - np.asarray(med), 0.0)
        ax.bar(
            xs, med, width, yerr=[np.zeros_like(upper), upper], capsize=2, color=COLORS[i % len(COLORS)], label=method
        )
    ax.set_xticks(range(len(datasets)), datasets, rotation=35, ha="right", fontsize=7)
    ax.set_yscale("log")
    ax.set_ylabel("per-scan time (ms): median, whisker to p95")
    ax.set_title("Runtime per scan on each dataset's own odometry", fontsize=9)
    ax.grid(alpha=0.3, axis="y", which="both")
    ax.legend(fontsize=7)
    fig.savefig(path, format="png", bbox_inches="tight")
    plt.close(fig)
    return path
