"""The network of places drawn in the manner of the thesis's Figure 4.2.

Left: each live place as a circle whose radius is 0.4 times its extent
(``extent_m``: half the diagonal of the box of its own surfaces' midpoints;
scaled so neighbours do not cover each other), at its centre in the run's map
frame, with a line for each link between places (an exit known to lead from
one to the other). Right: each place's metric map in its own frame (x along
the heading it was entered with), its own surfaces dark, those seen only
through its exits light (Figure 4.2's dotted "surfaces belonging to P2 but
seen from P1"), its exits in red. Drawn from ``places.json``
(:mod:`albot1.methods.albot1.places.network`) alone.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from albot1.report.tight_png import save_tight_png


def render_places(record: dict[str, Any], path: Path, title: str = "") -> None:
    """Write the figure for ``record`` (a ``places.json`` document) to ``path`` (PNG)."""
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle

    live = [p for p in record["places"] if p["merged_into"] is None]
    cols = max(1, math.ceil(math.sqrt(len(live))))
    rows = max(1, math.ceil(len(live) / cols))
    fig = Figure(figsize=(6 + 2.2 * cols, max(5.0, 2.2 * rows)), dpi=100)
    grid = fig.add_gridspec(rows, 1 + cols, width_ratios=[1.5 * cols] + [1] * cols)
    ax = fig.add_subplot(grid[:, 0])
    by_id = {p["id"]: p for p in live}
    for link in record["links"]:
        a, b = by_id.get(link["place"]), by_id.get(link["to_place"])
        if a is not None and b is not None:
            ax.plot([a["centre_map"][0], b["centre_map"][0]], [a["centre_map"][1], b["centre_map"][1]], "k-", lw=1)
    for p in live:
        (x, y), r = p["centre_map"], max(0.4 * p["extent_m"], 0.3)
        ax.add_patch(Circle((x, y), r, facecolor="tab:blue", alpha=0.15, edgecolor="tab:blue"))
        ax.text(x, y, f"P{p['id']}", ha="center", va="center", fontsize=9)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_title("network of places (circle radius: 0.4 x extent)", fontsize=9)
    for k, p in enumerate(live):
        _place_map(fig.add_subplot(grid[k // cols, 1 + k % cols]), p, LineCollection)
    fig.suptitle(title or "places", fontsize=10)
    save_tight_png(fig, path)  # one layout pass instead of bbox_inches="tight"'s three


def _place_map(ax: Any, place: dict[str, Any], line_collection: Any) -> None:
    surfaces = np.asarray(place["surfaces"], dtype=float).reshape(-1, 2, 2)
    through = np.asarray(place.get("through", [False] * len(surfaces)), dtype=bool)
    if len(surfaces):
        ax.add_collection(line_collection(list(surfaces[~through]), colors="0.15", linewidths=0.8))
        if through.any():
            ax.add_collection(line_collection(list(surfaces[through]), colors="0.7", linewidths=0.6, linestyles=":"))
    for e in place["exits"]:
        s = e["segment"]
        ax.plot([s[0], s[2]], [s[1], s[3]], "r-", lw=2)
    ax.plot([0.0], [0.0], "k^", ms=4)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"P{place['id']}: {len(place['visits'])} visit(s)", fontsize=8)
