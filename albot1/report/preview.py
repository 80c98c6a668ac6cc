"""The PNG preview stored in each run folder: map + trajectory (+ reference); ``places.png`` for a network.

The reference is drawn after a rigid least-squares alignment onto the
estimate so that both share a frame; the picture is for eyes, the numbers
come from the metrics.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from albot1.atomic import atomic_write
from albot1.contract import RunResult
from albot1.metrics.alignment import align
from albot1.report.places_plot import render_places
from albot1.report.tick_memo import share_tick_updates
from albot1.report.tight_png import save_tight_png


def render_preview(result: RunResult, path: Path, max_points: int = 200_000) -> None:
    """Draw ``result``'s map and trajectory into ``path`` (and ``places.png`` beside it for a network of places).

    Every ``albot1 bench`` cell draws one, in a process forked for that cell,
    so the preview is a fixed cost per cell (issue 24). Its axes' ticks are
    worked out once per draw (:func:`~albot1.report.tick_memo.share_tick_updates`,
    as in the reports): matplotlib otherwise updates each axis's ticks and
    measures their labels again for the title's place, the axis label's and
    each spine's, with the same result each time, so the pixels are the same
    (``docs/benchmarking.md``, "Session 22").
    """
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    share_tick_updates()
    fig = Figure(figsize=(7, 7), dpi=110)  # no pyplot: nothing to register or close, Agg is the canvas
    ax = fig.add_subplot()
    data = result.map
    if data.points is not None and len(data.points):
        pts = np.asarray(data.points)
        if len(pts) > max_points:
            pts = pts[np.random.default_rng(0).choice(len(pts), max_points, replace=False)]
        ax.scatter(pts[:, 0], pts[:, 1], s=0.2, c="0.35", linewidths=0, label="map points")
    if data.segments is not None and len(data.segments):
        seg = np.asarray(data.segments).reshape(-1, 2, 2)
        ax.add_collection(LineCollection(list(seg), colors="tab:green", linewidths=0.8, label="map surfaces"))
    if result.reference is not None and len(result.reference) > 2:
        ref, _ = align(result.reference, result.poses, "rigid")
        ax.plot(ref[:, 0], ref[:, 1], color="tab:orange", lw=0.8, label="reference (aligned)")
    ax.plot(result.poses[:, 0], result.poses[:, 1], color="tab:blue", lw=0.8, label=f"{result.method} estimate")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(
        f"{result.method} on {result.dataset} [{result.preset}, {result.degradation}, seed {result.seed}]", fontsize=9
    )
    ax.legend(loc="upper right", fontsize=7)  # "best" scans every map point: slow
    save_tight_png(fig, path)  # one layout pass instead of bbox_inches="tight"'s three
    places = result.files.get("places.json")
    if isinstance(places, dict):  # a method with a network of places (albot1-places): Figure 4.2 beside it
        title = f"{result.method} on {result.dataset} [{result.preset}, {result.degradation}, seed {result.seed}]"
        atomic_write(path.parent / "places.png", lambda p: render_places(places, p, title))
