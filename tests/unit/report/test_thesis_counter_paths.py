"""The thesis page reads a method's counters and the places metric's judgement of them by one rule."""

from __future__ import annotations

import pytest

from albot1.report.thesis.evidence import counter_path, metric_column


@pytest.mark.parametrize(
    ("name", "path"),
    [
        ("places", "updates.counters.places"),  # the method's own counters
        ("places_created", "updates.counters.places_created"),
        ("exit_prediction_aligned_mean_m", "updates.counters.exit_prediction_aligned_mean_m"),
        ("revisits_true", "places.revisits_true"),  # judged against the reference: the places metric's block
        ("revisit_precision", "places.revisit_precision"),
        ("revisit_recall", "places.revisit_recall"),
        ("crossings_missed", "places.exits.crossings_missed"),
        ("exit_prediction_not_aligned_true_mean_m", "places.exits.exit_prediction_not_aligned_true_mean_m"),
    ],
)
def test_a_counter_name_leads_to_its_numeric_field_of_metrics_json(name: str, path: str) -> None:
    assert counter_path(name) == path
    assert metric_column(path) is not None  # a numeric field of metrics.json in this version


def test_an_exit_prediction_counter_absent_for_want_of_a_comparison_says_so() -> None:
    """The mapper counts its exit predictions only when it compared one: the places metric says why none was."""
    from pathlib import Path

    from albot1.bench.grid import Cell
    from albot1.metrics.record import MetricsRecord
    from albot1.records import parse_record
    from albot1.report.collect import CellRecord
    from albot1.report.thesis.evidence import Evidence, Lookup

    why = "no exit prediction compared: no place was recognised (no re-visit claimed), so none was made"
    exits = {
        "exit_predictions": [],
        "crossing_scans": 15,
        "exit_prediction_aligned_true_mean_m": None,
        "exit_prediction_not_aligned_true_mean_m": None,
        "crossings_true": 0,
        "crossings_false": 0,
        "crossings_missed": 0,
        "exit_predictions_reason": why,
    }
    places = {
        "units": {},
        "rule": "rooms",
        "rooms": [],
        "buffer_m": None,
        "min_overlap": None,
        "claims": 0,
        "claims_true": [],
        "revisits_true": 0,
        "revisits_false": 0,
        "revisits_missed": 0,
        "revisits_actual": 0,
        "revisit_precision": None,
        "revisit_recall": None,
        "visits": [],
        "exits": exits,
    }
    updates = {"units": "counts", "views": 10, "updates": 2, "updates_per_view": 0.2, "counters": {"places": 1}}
    run = {"key": "k", "method": "m", "dataset": "d", "preset": "p", "degradation": "none", "seed": 0, "scans": 10}
    run["has_reference"] = True
    metrics = parse_record(MetricsRecord, {"run": run, "updates": updates, "places": places}, "metrics.json")
    record = CellRecord(
        Cell("s", "d", "d", "m", "m", "p", "none", 0, "k", "v", 1, 1), "done", Path("/x"), None, metrics, None
    )
    ev = Evidence([])
    for name in ("exit_predictions_compared", "exit_prediction_aligned_mean_m"):
        assert ev.number(Lookup(record, None), counter_path(name), "x").missing == why
    assert ev.number(Lookup(record, None), counter_path("merges_refused"), "x").missing == (
        "the run reports no counter 'merges_refused' (its method or version does not count it)"
    )
