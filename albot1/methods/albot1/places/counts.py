"""The places mapper's counters: what it counted, the network's size and the exit predictions compared."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from albot1.methods.albot1.places.exits import ExitTracker
from albot1.methods.albot1.places.memory import PlaceNetwork


@dataclass
class PlacesCounts:
    """What the places mapper counts as it runs (its counters in ``result.json``)."""

    exits_crossed: int = 0
    revisits_by_structure: int = 0
    revisits_by_exit: int = 0
    match_attempts: int = 0
    merges_refused: int = 0
    updates_forced: int = 0


def places_counters(
    base: dict[str, int | float],
    network: PlaceNetwork,
    exits: ExitTracker,
    c: PlacesCounts,
    crossings: list[dict[str, Any]],
) -> dict[str, int | float]:
    """The chapter-3 mapper's counters ``base`` with the places layer's added."""
    counters = dict(base)
    counters.update(
        places_created=len(network.places),
        places=len(network.live_places()),
        places_merged=len(network.places) - len(network.live_places()),
        visits=len(network.visits),
        exits_tracked=exits.confirmed,
        exit_detections=exits.detections,
        exits_crossed=c.exits_crossed,
        revisits_confirmed=c.revisits_by_structure + c.revisits_by_exit,
        revisits_by_structure=c.revisits_by_structure,
        revisits_by_exit=c.revisits_by_exit,
        match_attempts=c.match_attempts,
        merges_refused=c.merges_refused,
        updates_forced=c.updates_forced,
    )
    compared = [r["prediction"] for r in crossings if r["prediction"] is not None]
    if compared:
        counters["exit_predictions_compared"] = len(compared)
        counters["exit_prediction_aligned_mean_m"] = float(np.mean([p["aligned_distance_m"] for p in compared]))
        counters["exit_prediction_not_aligned_mean_m"] = float(np.mean([p["not_aligned_distance_m"] for p in compared]))
    return counters
