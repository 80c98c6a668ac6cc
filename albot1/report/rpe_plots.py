"""Relative error against segment length: box plots across methods (the rpg_trajectory_evaluation figure).

For each segment length of the drift sweep the route is long enough for
(:data:`albot1.metrics.drift.DEFAULT_LENGTHS_M`), every segment starting at
each metre of reference travel (:func:`albot1.metrics.drift.segment_pairs`)
gives one translation error (m) and one rotation error (deg); a box per
method shows their quartiles, whiskers at 1.5 IQR, outliers left out
(their extent is in the drift sweep of ``metrics.json``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.metrics.drift import DEFAULT_LENGTHS_M, segment_errors, segment_pairs
from albot1.report.collect import CellRecord
from albot1.report.plots import has_reference, log_floor, pyplot, representative, save, value_axis


def segment_error_sets(records: list[CellRecord]) -> tuple[list[float], dict[str, list[NDArray[np.float64]]]]:
    """(lengths with segments, method -> per length an ``(K, 2)`` array of translation m, rotation deg errors)."""
    runs = {}
    for label, rec in representative(records).items():
        run = rec.stored_run()
        if run.reference is not None and has_reference(run.reference, run.poses):
            runs[label] = (run.poses, run.reference)
    lengths: list[float] = []
    errors: dict[str, list[NDArray[np.float64]]] = {label: [] for label in runs}
    for length in DEFAULT_LENGTHS_M:
        pairs = {label: segment_pairs(ref, length) for label, (_, ref) in runs.items()}
        if not any(len(p) for p in pairs.values()):
            continue
        lengths.append(length)
        for label, (poses, ref) in runs.items():
            p = pairs[label]
            errors[label].append(segment_errors(poses, ref, p) if len(p) else np.empty((0, 2)))
    return lengths, errors


def plot_rpe_boxes(records: list[CellRecord], dataset: str, path: Path, colors: dict[str, str]) -> Path | None:
    """Two panels (translation, rotation): per segment length, one box per method."""
    from matplotlib.patches import Patch

    lengths, errors = segment_error_sets(records)
    if not lengths or not errors:
        return None
    plt = pyplot()
    methods = list(errors)
    width = 0.8 / len(methods)
    fig, axes = plt.subplots(2, 1, figsize=(max(7.0, 1.1 * len(lengths) * max(1, len(methods) / 3)), 7.0), sharex=True)
    fig.set_layout_engine("constrained")
    for panel, (ax, unit, name) in enumerate(
        zip(axes, ("m", "deg"), ("translation error (m)", "rotation error (deg)"))
    ):
        floor = log_floor([e[:, panel] for sets in errors.values() for e in sets if len(e)])
        clipped: list[str] = []
        for i, label in enumerate(methods):
            data = []
            for e in errors[label]:
                values = e[:, panel] if len(e) else np.array([np.nan])
                if floor is not None:
                    if (values < floor).any():
                        clipped.append(label)
                    values = np.maximum(values, floor)
                data.append(values[np.isfinite(values)])
            positions = np.arange(len(lengths)) + (i - (len(methods) - 1) / 2) * width
            _boxes(ax, data, positions, width * 0.85, colors.get(label, "C0"))
        value_axis(ax, floor, sorted(set(clipped)), unit)
        ax.set_ylabel(name)
        ax.grid(alpha=0.3, axis="y", which="both", lw=0.5)
    axes[-1].set_xticks(range(len(lengths)), [f"{length:g}" for length in lengths])
    axes[-1].set_xlabel("segment length along the reference (m)")
    handles = [Patch(facecolor=colors.get(label, "C0"), edgecolor="0.2", label=label) for label in methods]
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
    fig.suptitle(f"{dataset}: relative error per segment length (a segment starts every metre)", fontsize=9)
    return save(fig, path)


def _boxes(ax: Any, data: list[NDArray[np.float64]], positions: NDArray[Any], width: float, color: str) -> None:
    keep = [k for k, d in enumerate(data) if len(d)]
    if not keep:
        return
    parts = ax.boxplot(
        [data[k] for k in keep],
        positions=positions[keep],
        widths=width,
        showfliers=False,
        patch_artist=True,
        manage_ticks=False,
        medianprops={"color": "black", "lw": 1.0},
        whiskerprops={"color": "0.3"},
        capprops={"color": "0.3"},
    )
    for box in parts["boxes"]:
        box.set_facecolor(color)
        box.set_alpha(0.85)
        box.set_edgecolor("0.2")
