"""The thesis page's experiments find their datasets in the thesis suite file by tag, never by a copied label."""

from __future__ import annotations

from typing import Any

import pytest

from albot1.bench.suite import parse_suite
from albot1.report.errors import ReportError
from albot1.report.thesis.experiments.datasets import ThesisDatasets, thesis_datasets

TAGGED = [
    ("world-a", "start-stop-square"),
    ("world-b", "dense-views"),
    ("world-b?views=1:10", "sparse-views"),
    ("loop", "places-single-loop"),
    ("loop?start=1", "places-single-loop"),
    ("double", "places-double-loop"),
    ("loop?laps=2", "places-two-laps"),
]


def _suite(entries: list[dict[str, Any]], degradations: list[str] | None = None) -> Any:
    data = {
        "grid": {"degradations": ["bias:0.1:1"] if degradations is None else degradations},
        "methods": [{"name": "odometry"}],
        "datasets": entries,
    }
    return parse_suite(data, name="t", source="t.toml")


def _entries() -> list[dict[str, Any]]:
    return [{"name": "*", "optional": True}] + [{"name": name, "tags": [tag]} for name, tag in TAGGED]


def test_each_experiment_reads_the_labels_of_its_tagged_entries_in_suite_order() -> None:
    entries = _entries()
    entries[2]["limit"] = 50  # a sliced entry is read by the label its runs get
    ds = ThesisDatasets.from_suite(_suite(entries))
    assert ds == ThesisDatasets(
        square="world-a",
        induced="bias:0.1:1",
        dense="world-b[:50]",
        sparse="world-b?views=1:10",
        places_starts=("loop", "loop?start=1"),
        double_loop="double",
        two_laps="loop?laps=2",
    )


def test_tags_change_no_run_options() -> None:
    suite = _suite(_entries())
    options = suite.options_for("world-b")
    assert options is not None and "tags" not in options.model_dump(exclude_unset=True)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda e: e.pop(2), r"suite 't': no dataset entry tagged 'dense-views'"),
        (lambda e: e[3].update(tags=["dense-views"]), r"2 dataset entries tagged 'dense-views'; expected one"),
        (lambda e: e.append({"name": "world-b", "skip": True}), r"no dataset entry tagged 'dense-views'"),
        (lambda e: e.append({"name": "w*", "tags": ["places-two-laps"]}), r"tagged 'places-two-laps' is a pattern"),
    ],
)
def test_a_missing_doubled_skipped_or_pattern_tag_is_a_clear_error(change: Any, message: str) -> None:
    entries = _entries()
    change(entries)
    with pytest.raises(ReportError, match=message):
        ThesisDatasets.from_suite(_suite(entries))


def test_experiment_3_needs_exactly_one_induced_error() -> None:
    with pytest.raises(ReportError, match=r"`world-a` sweeps 2 degradations \(thesis, bias:0.1:1\); expected one"):
        ThesisDatasets.from_suite(_suite(_entries(), ["thesis", "bias:0.1:1"]))


def test_the_project_suite_tags_every_experiment() -> None:
    ds = thesis_datasets()
    assert len(ds.places_starts) == 3 and ds.induced == "thesis"
    assert len({ds.square, ds.dense, ds.sparse, *ds.places_starts, ds.double_loop, ds.two_laps}) == 8  # all distinct
