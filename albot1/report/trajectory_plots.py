"""Trajectory figures of a dataset: every method over the reference, and where each one goes wrong.

* :func:`plot_trajectories`: every method's trajectory over the reference,
  rigidly aligned as for the ATE (own frames without a reference).
* :func:`plot_ape_map`: per method, its trajectory coloured by the absolute
  position error of each pose, with a colour bar, over the reference drawn
  dashed (what ``evo_ape --plot_mode xy`` shows).
* :func:`plot_error_vs_distance`: the same per-pose error against the
  distance travelled along the reference, one line per method.

The per-pose error is :func:`albot1.metrics.ate.position_errors` under the
rigid alignment: the numbers whose RMSE is the table's ATE.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.geometry import se2
from albot1.metrics.ate import position_errors
from albot1.report.collect import CellRecord
from albot1.report.plots import (
    REFERENCE_COLOR,
    Extent,
    aligned_poses,
    dense,
    has_reference,
    label_grid,
    log_floor,
    panel_layout,
    pyplot,
    representative,
    save,
    value_axis,
)

APE_COLORMAP = "viridis"
#: A trajectory spanning less than this fraction of the figure is drawn with circled ends so it stays visible.
TINY_FRACTION = 0.01


def run_tag(rec: CellRecord) -> str:
    """``[degradation, seed N]``: which of a method's runs a figure shows (the representative one)."""
    return f"[{rec.cell.degradation}, seed {rec.cell.seed}]"


def _with_reference(records: list[CellRecord]) -> dict[str, tuple[CellRecord, NDArray[np.float64]]]:
    """method label -> (representative run, its reference) for the runs that have reference poses."""
    out = {}
    for label, rec in representative(records).items():
        run = rec.stored_run()
        if run.reference is not None and has_reference(run.reference, run.poses):
            out[label] = (rec, run.reference)
    return out


def plot_trajectories(records: list[CellRecord], dataset: str, path: Path, colors: dict[str, str]) -> Path | None:
    """Every method's trajectory over the reference (aligned as for the ATE), one axes, legend outside."""
    runs = representative(records)
    if not runs:
        return None
    plt = pyplot()
    lines: list[tuple[str, NDArray[np.float64]]] = []
    tags: dict[str, str] = {}
    reference = None
    for label, rec in runs.items():
        run = rec.stored_run()
        if reference is None and run.reference is not None and has_reference(run.reference, run.poses):
            reference = run.reference
        lines.append((label, aligned_poses(run.poses, run.reference)))
        tags[label] = run_tag(rec)
    extent = Extent.around([xy for _, xy in lines] + ([reference] if reference is not None else []))
    _, _, size = panel_layout(extent, 1, panel_max_in=7.5)
    fig, ax = plt.subplots(figsize=size, layout="constrained")
    if reference is not None:
        ax.plot(reference[:, 0], reference[:, 1], color=REFERENCE_COLOR, lw=1.6, alpha=0.45, label="reference")
    for label, xy in lines:
        span = float(np.ptp(xy[:, :2], axis=0).max()) if len(xy) else 0.0
        if span < TINY_FRACTION * max(extent.width, extent.height):  # would vanish under its own line width
            ax.plot(
                xy[:, 0],
                xy[:, 1],
                color=colors.get(label, "C0"),
                lw=1.0,
                marker="o",
                ms=7,
                mfc="none",
                markevery=[0, len(xy) - 1],
                label=f"{label} {tags[label]} (moves {span:.2g} m: circled)",
                zorder=3,
            )
        else:
            ax.plot(xy[:, 0], xy[:, 1], color=colors.get(label, "C0"), lw=1.0, label=f"{label} {tags[label]}")
    extent.apply(ax)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(alpha=0.25, lw=0.5)
    aligned = "rigidly aligned to the reference" if reference is not None else "each in its own frame (no reference)"
    ax.set_title(f"{dataset}: trajectories, {aligned}", fontsize=9)
    fig.legend(loc="outside lower center", ncols=min(len(lines) + 1, 4), fontsize=8, frameon=False)
    return save(fig, path)


def plot_ape_map(records: list[CellRecord], dataset: str, path: Path, colors: dict[str, str]) -> Path | None:
    """Per method: its trajectory coloured by per-pose position error (m, colour bar), over the dashed reference."""
    from matplotlib.collections import LineCollection

    runs = _with_reference(records)
    if not runs:
        return None
    plt = pyplot()
    shapes = {label: aligned_poses(rec.stored_run().poses, ref) for label, (rec, ref) in runs.items()}
    extent = Extent.around([*shapes.values(), *(ref for _, ref in runs.values())])
    rows, cols, size = panel_layout(extent, len(runs), extra_height_in=0.8)
    fig, axes = plt.subplots(rows, cols, figsize=size, sharex=True, sharey=True, squeeze=False, layout="constrained")
    errors_of = {label: position_errors(rec.stored_run().poses, ref, "rigid") for label, (rec, ref) in runs.items()}
    # one colour scale for every panel, so that colours compare across methods
    top = max(float(e.max()) for e in errors_of.values() if len(e)) if any(len(e) for e in errors_of.values()) else 0.0
    top = top if top > 0 else 1.0
    lc = None
    for ax, (label, (rec, ref)) in zip(axes.flat, runs.items()):
        xy = shapes[label]
        errors = errors_of[label]
        ax.plot(ref[:, 0], ref[:, 1], color="0.55", lw=0.9, ls="--", zorder=1)
        segments = np.stack([xy[:-1, :2], xy[1:, :2]], axis=1)
        lc = dense(LineCollection(list(segments), cmap=APE_COLORMAP, linewidths=1.6, zorder=2))
        lc.set_array((errors[:-1] + errors[1:]) / 2)
        lc.set_clim(0.0, top)
        ax.add_collection(lc)
        rmse = float(np.sqrt(np.mean(errors**2)))
        ax.set_title(
            f"{label} {run_tag(rec)}: ATE RMSE {rmse:.3g} m, max {float(errors.max()):.3g} m", fontsize=8, color="0.1"
        )
        for spine in ax.spines.values():
            spine.set_edgecolor(colors.get(label, "0.3"))
            spine.set_linewidth(1.4)
        extent.apply(ax)
        ax.tick_params(labelsize=7)
    if lc is not None:
        bar = fig.colorbar(
            lc, ax=axes, location="right" if extent.aspect < 2.5 else "bottom", shrink=0.85, pad=0.02, aspect=40
        )
        bar.set_label(f"APE (m), one scale for all panels: 0 to {top:.3g} m", fontsize=7)
        bar.ax.tick_params(labelsize=6)
    label_grid(axes, len(runs))
    fig.suptitle(
        f"{dataset}: absolute position error per pose (rigid alignment; dashed: reference; frame colour: method)",
        fontsize=9,
    )
    return save(fig, path)


def plot_error_vs_distance(records: list[CellRecord], dataset: str, path: Path, colors: dict[str, str]) -> Path | None:
    """Per-pose position error (m) against distance travelled along the reference (m), one line per method."""
    runs = _with_reference(records)
    if not runs:
        return None
    plt = pyplot()
    series: dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}
    for label, (rec, ref) in runs.items():
        series[label] = (se2.cumulative_length(ref), position_errors(rec.stored_run().poses, ref, "rigid"))
    floor = log_floor(e for _, e in series.values())
    fig, ax = plt.subplots(figsize=(9, 4.2), layout="constrained")
    clipped: list[str] = []
    for label, (travel, errors) in series.items():
        shown = errors
        if floor is not None:
            if (errors < floor).any():
                clipped.append(label)
            shown = np.maximum(errors, floor)
        ax.plot(travel, shown, color=colors.get(label, "C0"), lw=1.0, label=label)
    value_axis(ax, floor, clipped, "m")
    ax.set_xlabel("distance travelled along the reference (m)")
    ax.set_ylabel("absolute position error (m)")
    ax.grid(alpha=0.3, which="both", lw=0.5)
    ax.set_title(f"{dataset}: position error along the route (rigid alignment, as for the ATE)", fontsize=9)
    fig.legend(loc="outside right upper", fontsize=8, frameon=False)
    return save(fig, path)
