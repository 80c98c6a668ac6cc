"""The maps of a dataset: one panel per method, every map in the reference's frame, the reference drawn.

Each method's map is moved by the rigid motion that aligns its trajectory
to the reference (the map is never aligned on its own: that would hide a
wrong trajectory), so all panels share one frame and one scale in metres.
Line maps (Albot1's surfaces) are drawn as lines; point maps either as an
occupancy grid (the cells a point falls in, at a resolution that follows
the map's size: the readable default) or as the points themselves
(``style="points"``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from albot1.report.collect import CellRecord
from albot1.report.plots import (
    REFERENCE_COLOR,
    Extent,
    aligned_poses,
    dense,
    has_reference,
    label_grid,
    panel_layout,
    pyplot,
    representative,
    robust_points,
    save,
    transform_points,
)
from albot1.report.provenance import separate_data

MapStyle = Literal["grid", "points"]
MAX_MAP_POINTS = 60_000
#: Occupancy cells along a panel's longer side (about two pixels each at the report's resolution, so thin
#: walls stay visible); never finer than :data:`MIN_CELL_M`.
GRID_CELLS = 350
MIN_CELL_M = 0.05
MAP_COLOR = "0.45"


def occupancy(points: NDArray[np.float64], extent: Extent) -> tuple[NDArray[np.float64], float]:
    """A masked image of the cells of ``extent`` that hold at least one point, and the cell size (m)."""
    cell = max(MIN_CELL_M, max(extent.width, extent.height) / GRID_CELLS)
    nx = max(1, int(np.ceil(extent.width / cell)))
    ny = max(1, int(np.ceil(extent.height / cell)))
    counts, _, _ = np.histogram2d(
        points[:, 0], points[:, 1], bins=(nx, ny), range=((extent.x0, extent.x1), (extent.y0, extent.y1))
    )
    return np.ma.masked_equal((counts.T > 0).astype(float), 0.0), cell


def _draw_map(ax: Any, rec: CellRecord, extent: Extent, style: MapStyle) -> None:
    from matplotlib.collections import LineCollection
    from matplotlib.colors import ListedColormap

    run = rec.stored_run()
    data = rec.stored_map()
    if data.points is not None and len(data.points):
        pts = transform_points(np.asarray(data.points, dtype=float), run.poses, run.reference)
        if style == "grid":
            image, _ = occupancy(pts, extent)
            ax.imshow(
                image,
                extent=(extent.x0, extent.x1, extent.y0, extent.y1),
                origin="lower",
                cmap=ListedColormap([MAP_COLOR]),
                interpolation="nearest",
                zorder=1,
            )
        else:
            if len(pts) > MAX_MAP_POINTS:
                pts = pts[np.random.default_rng(0).choice(len(pts), MAX_MAP_POINTS, replace=False)]
            ax.scatter(pts[:, 0], pts[:, 1], s=0.2, c=MAP_COLOR, linewidths=0, rasterized=True, zorder=1)
    if data.segments is not None and len(data.segments):
        ends = np.asarray(data.segments, dtype=float).reshape(-1, 2)
        seg = transform_points(ends, run.poses, run.reference).reshape(-1, 2, 2)
        ax.add_collection(dense(LineCollection(list(seg), colors="0.15", linewidths=0.8, zorder=2)))


def _extent(runs: dict[str, CellRecord]) -> Extent:
    parts: list[NDArray[np.float64]] = []
    for rec in runs.values():
        run = rec.stored_run()
        parts.append(aligned_poses(run.poses, run.reference))
        if run.reference is not None:
            parts.append(run.reference)
        geometry = rec.map_geometry()
        if len(geometry):
            parts.append(robust_points(transform_points(np.asarray(geometry, dtype=float), run.poses, run.reference)))
    return Extent.around(parts)


def draws_maps(records: list[CellRecord]) -> bool:
    """Whether :func:`plot_maps` draws a figure for ``records`` (one dataset's): some method completed a run."""
    return bool(representative(records))


def maps_drawn(records: list[CellRecord]) -> set[str]:
    """The datasets whose maps figure a report of a store of ``records`` (as collected) draws, by report label.

    Known from the store alone, before any drawing: the thesis report links the default report's maps
    figures while that report is still being drawn (``make bench`` builds them at once). The labels are the
    report's (:func:`~albot1.report.provenance.separate_data`), as its figure files are named.
    """
    by_dataset: dict[str, list[CellRecord]] = {}
    for rec in separate_data(records):
        by_dataset.setdefault(rec.cell.dataset_label, []).append(rec)
    return {dataset for dataset, recs in by_dataset.items() if draws_maps(recs)}


def plot_maps(
    records: list[CellRecord], dataset: str, path: Path, colors: dict[str, str], *, style: MapStyle = "grid"
) -> Path | None:
    """One panel per method (same frame, same scale): its map, its trajectory and the reference trajectory."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    if not draws_maps(records):
        return None
    runs = representative(records)
    plt = pyplot()
    extent = _extent(runs)
    rows, cols, size = panel_layout(extent, len(runs))
    fig, axes = plt.subplots(rows, cols, figsize=size, sharex=True, sharey=True, squeeze=False, layout="constrained")
    framed = False
    for ax, (label, rec) in zip(axes.flat, runs.items()):
        run = rec.stored_run()
        _draw_map(ax, rec, extent, style)
        if run.reference is not None and has_reference(run.reference, run.poses):
            framed = True
            ax.plot(run.reference[:, 0], run.reference[:, 1], color=REFERENCE_COLOR, lw=0.8, ls="--", zorder=3)
        xy = aligned_poses(run.poses, run.reference)
        ax.plot(xy[:, 0], xy[:, 1], color=colors.get(label, "C0"), lw=1.0, zorder=4)
        ax.set_title(f"{label} [{rec.cell.degradation}, seed {rec.cell.seed}]", fontsize=9)
        if rec.cell.trajectory is not None:  # another system's file (albot1.bench.external): no map to draw
            ax.text(0.5, 0.5, "no map: an external trajectory file", transform=ax.transAxes, ha="center", va="center",
                    fontsize=8, color="0.35")  # fmt: skip
        extent.apply(ax)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.2, lw=0.5)
    label_grid(axes, len(runs))
    handles: list[Any] = [Patch(color=MAP_COLOR, label="map" + (" (occupied cells)" if style == "grid" else ""))]
    if framed:
        handles.append(Line2D([], [], color=REFERENCE_COLOR, lw=0.8, ls="--", label="reference trajectory"))
    handles += [Line2D([], [], color=colors.get(label, "C0"), lw=1.2, label=f"{label} trajectory") for label in runs]
    fig.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 4), fontsize=8, frameon=False)
    frame = "aligned to the reference (rigid, as for the ATE)" if framed else "each in its own frame (no reference)"
    fig.suptitle(f"{dataset}: maps, {frame}", fontsize=10)
    return save(fig, path)
