"""The thesis page's own figures: Figure 3.17's update trace, the map animation, Figures 3.21-3.22's loop gap.

Every figure is drawn from stored runs (and, for the maps after each
update, from a replay checked against the stored run:
:mod:`albot1.report.thesis.replay`). Maps are drawn in the reference's frame
where the run has reference poses, moved by the rigid motion that aligns the
trajectory (as the report's other map figures), except the loop-gap maps:
the thesis draws those from the start, so they are anchored at the first
pose and the gap is the green line between the route's two ends.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.metrics.alignment import alignment_transform
from albot1.metrics.errors import MetricsError
from albot1.report.plots import (
    REFERENCE_COLOR,
    Extent,
    has_reference,
    label_grid,
    panel_layout,
    pyplot,
    robust_points,
    save,
    write_png,
)
from albot1.report.thesis.replay import Replay
from albot1.runs.folder import StoredRun

#: Panels of the update trace at most (Figure 3.17 shows 24 maps in four parts); the strip shows every update.
MAX_TRACE_PANELS = 24
#: Frames of the animation at most, and the largest GIF written (bytes): the report folder stays light.
MAX_FRAMES = 60
MAX_GIF_BYTES = 2_000_000
GIF_DPI = 90
GAP_COLOR = "#2ca02c"
NEW_COLOR = "#d62728"
VIEW_COLORS = {"initial": "0.3", "current": "#1f77b4", "previous": "#ff7f0e", "forced": "#9467bd"}


def frame_transform(run: StoredRun, how: str = "rigid") -> FloatArray:
    """The motion that puts the run's map frame into its reference's frame (identity without a reference)."""
    if run.reference is None or not has_reference(run.reference, run.poses):
        return np.zeros(3)
    try:
        return np.asarray(alignment_transform(run.poses, run.reference, "first" if how == "first" else "rigid"))
    except MetricsError:  # a degenerate trajectory: drawn in its own frame
        return np.zeros(3)


def _segments(transform: FloatArray, segments: FloatArray) -> FloatArray:
    ends = np.asarray(segments, dtype=float).reshape(-1, 2)
    if not len(ends):
        return np.empty((0, 2, 2))
    return np.asarray(se2.transform_points(transform, ends)).reshape(-1, 2, 2)


def _poses(transform: FloatArray, poses: FloatArray) -> FloatArray:
    return np.asarray(se2.compose(transform, poses)).reshape(-1, 3) if len(poses) else poses


def _extent(replay: Replay, transform: FloatArray) -> Extent:
    parts: list[FloatArray] = [_poses(transform, replay.run.poses)]
    if replay.run.reference is not None:
        parts.append(replay.run.reference)
    ends = [_segments(transform, s.segments).reshape(-1, 2) for s in replay.states]
    if ends:
        parts.append(robust_points(np.concatenate(ends)))
    return Extent.around(parts)


def _new_rows(now: FloatArray, before: FloatArray | None) -> NDArray[np.bool_]:
    """Which surfaces of ``now`` were not in the map before the update (the view's additions and edits)."""
    if before is None or not len(before):
        return np.ones(len(now), dtype=bool)
    known = {tuple(np.round(row, 9)) for row in before}
    return np.array([tuple(np.round(row, 9)) not in known for row in now], dtype=bool)


def _draw_state(ax: Any, replay: Replay, k: int, transform: FloatArray, *, highlight: bool = True) -> None:
    from matplotlib.collections import LineCollection

    state = replay.states[k]
    before = replay.states[k - 1].segments if k > 0 else None
    segs = _segments(transform, state.segments)
    new = _new_rows(state.segments, before) if highlight else np.zeros(len(segs), dtype=bool)
    if (~new).any():
        ax.add_collection(LineCollection(list(segs[~new]), colors="0.2", linewidths=0.7, zorder=2))
    if new.any():
        ax.add_collection(LineCollection(list(segs[new]), colors=NEW_COLOR, linewidths=0.9, zorder=3))
    path = _poses(transform, replay.run.poses[: state.scan + 1])
    ax.plot(path[:, 0], path[:, 1], color="#1f77b4", lw=0.7, alpha=0.6, zorder=1)
    at = _poses(transform, replay.run.poses[state.view_scan : state.view_scan + 1])
    if len(at):
        x, y, th = at[0]
        ax.plot([x], [y], marker="o", ms=3.5, color=VIEW_COLORS.get(state.view, "k"), zorder=4)
        ax.plot([x, x + 1.2 * math.cos(th)], [y, y + 1.2 * math.sin(th)], color="k", lw=0.8, zorder=4)


def save_png(fig: Any, png: Path) -> Path:
    """Write ``png`` only: the trace's many panels would make a vector twin of several MB and seconds to write."""
    write_png(fig, png)  # laid out in its one draw
    pyplot().close(fig)
    return png


def pick(count: int, most: int) -> list[int]:
    """``most`` indices spread evenly over ``range(count)``, first and last included (all when fewer)."""
    if count <= most:
        return list(range(count))
    return sorted({round(i * (count - 1) / (most - 1)) for i in range(most)})


def plot_update_trace(replay: Replay, path: Path, title: str, *, max_panels: int | None = None) -> Path:
    """Figure 3.17: the map after each update (at most ``max_panels``, default :data:`MAX_TRACE_PANELS`, evenly
    spread), the surfaces each update added or changed in red."""
    from matplotlib.lines import Line2D

    max_panels = MAX_TRACE_PANELS if max_panels is None else max_panels
    plt = pyplot()
    transform = frame_transform(replay.run)
    extent = _extent(replay, transform)
    shown = pick(len(replay.states), max_panels)
    rows, cols, size = panel_layout(extent, max(1, len(shown)), panel_max_in=2.6, extra_height_in=1.0)
    fig, axes = plt.subplots(rows, cols, figsize=size, sharex=True, sharey=True, squeeze=False, layout="constrained")
    for ax, k in zip(axes.flat, shown):
        _draw_state(ax, replay, k, transform)
        state = replay.states[k]
        ax.set_title(f"update {k}: scan {state.scan} ({state.view})", fontsize=7)
        extent.apply(ax)
        ax.tick_params(labelsize=6)
    label_grid(axes, len(shown))
    handles = [
        Line2D([], [], color="0.2", lw=0.8, label="map surfaces"),
        Line2D([], [], color=NEW_COLOR, lw=0.9, label="surfaces this update added or changed"),
        Line2D([], [], color="#1f77b4", lw=0.8, label="route so far"),
        *[
            Line2D([], [], color=c, marker="o", ls="", label=f"pose of the {v} view used")
            for v, c in VIEW_COLORS.items()
            if any(s.view == v for s in replay.states)
        ],
    ]
    fig.legend(handles=handles, loc="outside lower center", ncols=3, fontsize=7, frameon=False)
    note = "" if len(shown) == len(replay.states) else f" ({len(shown)} of {len(replay.states)} updates shown)"
    fig.suptitle(f"{title}: the map after each update{note}", fontsize=9)
    return save_png(fig, path)


def plot_trace_strip(replay: Replay, path: Path, title: str) -> Path:
    """Which views triggered an update: cumulative updates against the view index, one marker per update."""
    plt = pyplot()
    views = len(replay.run.poses)
    fig, ax = plt.subplots(figsize=(9.0, 2.8), layout="constrained")
    scans = np.array([s.scan for s in replay.states], dtype=float)
    counted = np.array([s.view != "initial" for s in replay.states])
    cumulative = np.cumsum(counted)
    ax.step(scans, cumulative, where="post", color="0.4", lw=0.9, label="updates so far")
    for view, color in VIEW_COLORS.items():
        mask = np.array([s.view == view for s in replay.states])
        if mask.any():
            ax.plot(scans[mask], cumulative[mask], ls="", marker="|", ms=9, color=color, label=f"{view} view")
    ax.plot([0, views - 1], [0, views - 1], color="0.75", lw=0.7, ls=":", label="one update per view")
    ax.set_xlim(0, max(1, views - 1))
    ax.set_ylim(0, max(1, views - 1) if cumulative.size == 0 else max(cumulative.max() * 1.1, 1.0))
    ax.set_xlabel("view (scan index)", fontsize=8)
    ax.set_ylabel("updates", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=7, frameon=False, loc="upper left")
    ax.set_title(
        f"{title}: {int(counted.sum())} updates for {views} views (marks: the view that triggered one)", fontsize=9
    )
    return save(fig, path)


def animate_map(replay: Replay, path: Path, title: str, *, max_frames: int | None = None, fps: int = 5) -> Path:
    """A GIF of the map after each update along the route (at most ``max_frames`` frames, default
    :data:`MAX_FRAMES`; under :data:`MAX_GIF_BYTES`).

    Rendered with matplotlib's Pillow writer (no ffmpeg). When the file is
    larger than :data:`MAX_GIF_BYTES` the frames are halved and it is drawn again.
    """
    from matplotlib.animation import FuncAnimation, PillowWriter

    plt = pyplot()
    transform = frame_transform(replay.run)
    extent = _extent(replay, transform)
    frames = MAX_FRAMES if max_frames is None else max_frames
    while True:
        shown = pick(len(replay.states), max(2, frames))
        aspect = extent.aspect
        width = 4.8 if aspect >= 1 else max(2.6, 4.2 * aspect)
        fig, ax = plt.subplots(figsize=(width, width / aspect + 0.5), dpi=GIF_DPI, layout="constrained")

        def draw(i: int, shown: list[int] = shown, ax: Any = ax) -> list[Any]:
            ax.clear()
            k = shown[i]
            _draw_state(ax, replay, k, transform, highlight=True)
            extent.apply(ax)
            ax.set_xticks([])
            ax.set_yticks([])
            state = replay.states[k]
            ax.set_title(f"{title}\nupdate {k} of {len(replay.states) - 1}, scan {state.scan}", fontsize=7)
            return []

        animation = FuncAnimation(fig, draw, frames=len(shown), blit=False)
        animation.save(str(path), writer=PillowWriter(fps=fps))
        plt.close(fig)
        if path.stat().st_size <= MAX_GIF_BYTES or frames <= 10:
            return path
        frames //= 2


def _draw_map(ax: Any, run: StoredRun, transform: FloatArray) -> None:
    from matplotlib.collections import LineCollection

    data = run.load_map()
    if data.segments is not None and len(data.segments):
        ax.add_collection(LineCollection(list(_segments(transform, data.segments)), colors="0.2", lw=0.7, zorder=2))
    if data.points is not None and len(data.points):
        pts = np.asarray(se2.transform_points(transform, np.asarray(data.points, dtype=float)))
        if len(pts) > 40_000:
            pts = pts[np.random.default_rng(0).choice(len(pts), 40_000, replace=False)]
        ax.scatter(pts[:, 0], pts[:, 1], s=0.15, c="0.35", linewidths=0, rasterized=True, zorder=1)


def plot_gap_maps(panels: list[tuple[str, StoredRun, str]], path: Path, title: str, *, columns: int) -> Path:
    """Figures 3.21-3.22: each run's map from its start, the green line joining the route's two ends.

    ``panels`` are (title, run, gap text) in row-major order, ``columns`` per row.
    """
    from matplotlib.lines import Line2D

    plt = pyplot()
    parts: list[FloatArray] = []
    transforms = []
    for _, run, _ in panels:
        transform = frame_transform(run, "first")
        transforms.append(transform)
        parts.append(_poses(transform, run.poses))
        if run.reference is not None:
            parts.append(run.reference)
    extent = Extent.around(parts)
    rows = max(1, math.ceil(len(panels) / columns))
    width = min(13.0 / columns, 3.6)
    fig, axes = plt.subplots(
        rows,
        columns,
        figsize=(columns * width + 0.6, rows * (width / extent.aspect + 0.5) + 0.9),
        sharex=True,
        sharey=True,
        squeeze=False,
        layout="constrained",
    )
    for ax, (name, run, gap), transform in zip(axes.flat, panels, transforms):
        _draw_map(ax, run, transform)
        if run.reference is not None and has_reference(run.reference, run.poses):
            ax.plot(run.reference[:, 0], run.reference[:, 1], color=REFERENCE_COLOR, lw=0.6, ls="--", zorder=3)
        xy = _poses(transform, run.poses)
        ax.plot(xy[:, 0], xy[:, 1], color="#1f77b4", lw=0.8, zorder=4)
        ax.plot([xy[0, 0], xy[-1, 0]], [xy[0, 1], xy[-1, 1]], color=GAP_COLOR, lw=2.0, zorder=5)
        ax.set_title(f"{name}\nloop gap {gap}", fontsize=8)
        extent.apply(ax)
        ax.tick_params(labelsize=6)
    label_grid(axes, len(panels))
    handles = [
        Line2D([], [], color="0.2", lw=0.8, label="map"),
        Line2D([], [], color="#1f77b4", lw=0.8, label="estimated route"),
        Line2D([], [], color=REFERENCE_COLOR, lw=0.6, ls="--", label="true route"),
        Line2D([], [], color=GAP_COLOR, lw=2.0, label="gap: estimated end to start"),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncols=4, fontsize=7, frameon=False)
    fig.suptitle(f"{title} (each map anchored at its first pose, as the thesis draws them)", fontsize=9)
    return save(fig, path)
