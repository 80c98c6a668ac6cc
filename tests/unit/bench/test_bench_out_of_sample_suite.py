"""The out-of-sample suite (benchmarks/out-of-sample.toml, issue 21): five more held-out logs, two never tuned on."""

from __future__ import annotations

from albot1.bench.suite import find_suite, load_suite
from albot1.data import catalog
from albot1.report.tuning import dataset_name, tuned_datasets

#: the logs of the suite; the first two are in no preset's [tuned_on] table, the others in gtsam-graph's
UNTOUCHED = {"freiburg-campus-corrected", "infinite-corridor-corrected"}
LOOKED_AT = {"acapulco-corrected", "freiburg-101-corrected", "orebro-corrected"}


def test_the_suite_runs_five_corrected_logs_the_generalisation_suite_does_not() -> None:
    suite = load_suite(find_suite("out-of-sample"))
    logs = {dataset_name(entry.name) for entry in suite.datasets}
    assert logs == UNTOUCHED | LOOKED_AT and logs <= set(catalog.names())
    assert not logs & {dataset_name(entry.name) for entry in load_suite(find_suite("generalisation")).datasets}
    assert all(entry.sweep is True for entry in suite.datasets)
    assert "odometry" in {m.name for m in suite.methods}  # the page pairs every method with it


def test_no_method_of_the_suite_is_tuned_on_campus_or_the_infinite_corridor() -> None:
    for entry in load_suite(find_suite("out-of-sample")).methods:
        tuned = set(tuned_datasets(entry.name, entry.preset) or ())
        assert not UNTOUCHED & tuned, entry.display
