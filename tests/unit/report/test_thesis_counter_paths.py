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
