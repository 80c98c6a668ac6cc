"""Update counts: how often a method changes its map per scan it sees.

Albot1's claim (Experiment 4: 1330 views, 470 updates) is that it updates
its map only when a view brings something new; baselines count the
analogous events (map insertions, keyframes, graph nodes, loop closures,
optimisations). All counters a method reported are passed through, so a
baseline's own counts appear under their own names.
"""

from __future__ import annotations

from typing import Any

from albot1.metrics.errors import MetricsError


def update_counts(counters: dict[str, Any]) -> dict[str, Any]:
    """The ``updates`` block: ``views``, ``updates``, ``updates_per_view`` and every other counter."""
    for key in ("views", "updates"):
        if key not in counters:
            found = ", ".join(counters) or "none"
            raise MetricsError(f"update counts: the run's counters lack {key!r} (found: {found})")
    views, updates = counters["views"], counters["updates"]
    return {
        "units": "counts",
        "views": views,
        "updates": updates,
        "updates_per_view": (updates / views) if views else None,
        "counters": {k: v for k, v in counters.items() if k not in ("views", "updates")},
    }
