"""The relation metric as a picture: per log, box plots of each method's relation errors, published values marked.

The relation metric (Kuemmerle et al. 2009) is the field's standard on the
Freiburg logs, but a table gives only its mean and spread. Here every
relation of the log that the run's scans cover gives one translation error
(m) and one rotation error (deg) (:func:`albot1.metrics.relations.relation_errors`
on the stored run, the numbers behind the ``relations`` block of
``metrics.json``; an external run's block looks relations up in every pose
of its file, the boxes in the poses matched to scans). A box per method
(its representative run, :func:`albot1.report.plots.representative`; the
tick says which degradation and seed) shows the quartiles, whiskers at
1.5 IQR, outliers as dots and the mean as a white diamond, on a log axis
when the errors span more than two decades (values under its floor drawn at
it, and said so). Published
figures for this log (``albot1/methods/baselines/published.toml``) follow as
black diamonds at their mean with their published std as an error bar,
labelled "published"; a log with a slice (``aces[:500]``) gets none, since
the published figures are over whole logs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.methods.baselines.published import published_systems
from albot1.metrics.errors import MetricsError
from albot1.metrics.relations import relation_errors
from albot1.report.collect import CellRecord
from albot1.report.plots import log_floor, pyplot, representative, save, value_axis

#: (metric of published.toml, axis label) per panel
PANELS = (("relation_translation_m", "translation error (m)"), ("relation_rotation_deg", "rotation error (deg)"))


def relation_error_sets(records: list[CellRecord]) -> dict[str, tuple[str, NDArray[np.float64], NDArray[np.float64]]]:
    """method label -> (``[degradation, seed]``, translation errors m, rotation errors deg) of its representative run.

    Runs without relations, or whose scans cover none of them, are left out.
    """
    out = {}
    for label, rec in representative(records).items():
        run = rec.stored_run()
        if run.relations is None or not len(run.relations) or not len(run.timestamps):
            continue
        try:
            errors, _ = relation_errors(run.timestamps, run.poses, run.relations, outside="exclude")
        except MetricsError:
            continue
        if not len(errors):
            continue
        tag = f"[{rec.cell.degradation}, seed {rec.cell.seed}]"
        out[label] = (tag, np.hypot(errors[:, 0], errors[:, 1]), np.degrees(np.abs(errors[:, 2])))
    return out


def published_marks(log: str) -> dict[str, list[tuple[str, float, float | None]]]:
    """metric -> ``(system label, mean, std or None)`` of the published figures on ``log`` (a whole catalog log)."""
    marks: dict[str, list[tuple[str, float, float | None]]] = {metric: [] for metric, _ in PANELS}
    for system in published_systems():
        for figure in system.figures:
            if figure.log == log and figure.metric in marks:
                marks[figure.metric].append((system.label, figure.mean, figure.std))
    return marks


def plot_relation_boxes(records: list[CellRecord], dataset: str, path: Path, colors: dict[str, str]) -> Path | None:
    """Translation and rotation relation errors per method, published figures beside them; None without relations."""
    sets = relation_error_sets(records)
    if not sets:
        return None
    marks = published_marks(dataset)
    plt = pyplot()
    slots = len(sets) + max(len(v) for v in marks.values())
    contexts = {sets[label][0] for label in sets}
    common = contexts.pop() if len(contexts) == 1 else None  # said once in the title, not under every box
    fig, axes = plt.subplots(1, 2, figsize=(min(18.0, 3.0 + 1.0 * slots), 5.2), layout="constrained")
    for ax, (column, (metric, axis_label)) in zip(axes, enumerate(PANELS)):
        labels = list(sets)
        raw: list[NDArray[np.float64]] = [sets[label][2] if column else sets[label][1] for label in labels]
        floor = log_floor(
            [*(r.tolist() for r in raw), [m for _, m, _ in marks[metric]]]
        )  # errors span decades: a log axis
        data = raw if floor is None else [np.maximum(values, floor) for values in raw]
        clipped = [label for label, values in zip(labels, raw) if floor is not None and (values < floor).any()]
        boxes = ax.boxplot(
            data, positions=range(len(labels)), widths=0.6, patch_artist=True, showmeans=True,
            meanprops={"marker": "D", "markerfacecolor": "white", "markeredgecolor": "black", "markersize": 5},
            flierprops={"marker": ".", "markersize": 2, "alpha": 0.5},
        )  # fmt: skip
        for patch, label in zip(boxes["boxes"], labels):
            patch.set_facecolor(colors.get(label, "C0"))
            patch.set_alpha(0.75)
        ticks = [
            f"{label}\n{sets[label][0]}\nN = {len(sets[label][1])}"
            if common is None
            else f"{label}\nN = {len(sets[label][1])}"
            for label in labels
        ]
        for i, (system, mean, std) in enumerate(marks[metric], start=len(labels)):
            ax.errorbar(
                [i], [mean], yerr=None if std is None else [[min(std, mean * 0.99)], [std]], fmt="D", color="black",
                markersize=6, capsize=4, lw=1.0,
            )  # fmt: skip
            ticks.append(f"{system}\npublished")
        ax.set_xticks(range(len(ticks)), ticks, fontsize=6.5, rotation=45, ha="right", rotation_mode="anchor")
        ax.set_ylabel(axis_label)
        value_axis(ax, floor, clipped, axis_label.split("(")[-1].rstrip(")"))
        ax.grid(alpha=0.3, axis="y", lw=0.5)
    fig.suptitle(
        f"{dataset}{'' if common is None else ' ' + common}: relation errors per method (boxes: quartiles, "
        "whiskers 1.5 IQR, white diamond: mean; black diamond: published mean ± std)",
        fontsize=9,
    )
    return save(fig, path)
