"""The thesis suite file: it parses, runs each experiment's methods, and pairs its public-log runs with the
default suite's by dataset label (the page joins the two stores on it)."""

from __future__ import annotations

from albot1.bench.suite import find_suite, load_suite
from albot1.data import catalog
from albot1.data.synthetic import worlds
from albot1.report.thesis.experiments.common import PLACES_VARIANTS, SLAM_BASELINES, VARIANTS
from albot1.report.thesis.experiments.datasets import thesis_datasets

#: The thesis's own experiments' datasets, found in the suite file by their tags.
_DS = thesis_datasets()
SQUARE, DENSE, SPARSE = _DS.square, _DS.dense, _DS.sparse
PLACES_STARTS, DOUBLE_LOOP, TWO_LAPS = _DS.places_starts, _DS.double_loop, _DS.two_laps

#: The standard logs on which the default suite runs Experiment 6's RBPF baseline (the thesis page reads it there).
RBPF_LOGS = ("aces", "intel", "mit-csail", "fr079")


def test_the_suite_is_named_thesis_and_holds_every_experiment() -> None:
    suite = load_suite(find_suite("thesis"))
    assert suite.name == "thesis"
    square = suite.options_for(SQUARE)
    assert square is not None and square.sweep is True and "thesis" in suite.grid.degradations
    assert square.methods is not None and set(square.methods) == {"odometry", *VARIANTS}
    for spacing in (DENSE, SPARSE):
        opts = suite.options_for(spacing)
        assert opts is not None and opts.methods is not None
        assert set(opts.methods) == {"odometry", *VARIANTS, *SLAM_BASELINES}
    default = load_suite(find_suite("default"))
    for places in (*PLACES_STARTS, DOUBLE_LOOP, TWO_LAPS):
        opts = suite.options_for(places)
        assert opts is not None and opts.methods is not None
        # The worlds the default suite also runs get Experiments 1-2's two variants it lacks.
        in_default = places in worlds.WORLDS and default.options_for(places) is not None
        extra = {"albot1:literal", "albot1:plus"} if in_default else set()
        assert set(opts.methods) == {*PLACES_VARIANTS, *extra}, places


def test_public_logs_get_the_default_suites_labels_and_only_the_variants_it_lacks() -> None:
    thesis = load_suite(find_suite("thesis"))
    default = load_suite(find_suite("default"))
    default_methods = {m.display for m in default.methods}
    for name in [*catalog.names(), *worlds.WORLDS]:
        ours, theirs = thesis.options_for(name), default.options_for(name)
        if name in (SQUARE, DENSE) or name.startswith("synthetic-places"):
            continue  # the thesis's own experiments
        if theirs is None:
            assert ours is None, name  # nothing to pair with
            continue
        assert ours is not None, name
        assert ours.label == theirs.label, name  # the same prefix: the page pairs the runs by label
        assert ours.methods is not None and set(ours.methods) == {"albot1:literal", "albot1:plus"}
        assert not set(ours.methods) & default_methods  # never a run the default suite makes already


def test_the_default_suite_runs_experiment_6s_baselines_on_the_standard_logs() -> None:
    default = load_suite(find_suite("default"))
    entries = {m.display: m for m in default.methods}
    for label in ("mrpt-rbpf", "mrpt-icp"):
        assert label in entries and entries[label].allow_failure, label
    for log in RBPF_LOGS:
        assert entries["mrpt-rbpf"].runs_on(log) and entries["mrpt-icp"].runs_on(log), log
    assert not entries["mrpt-rbpf"].runs_on("synthetic-office-loop")  # not on every dataset: its cost


def test_every_dataset_of_the_default_suite_gets_the_two_variants_it_lacks() -> None:
    """Experiments 1-2 compare literal, thesis and plus on the same datasets: none may lack a variant."""
    thesis = load_suite(find_suite("thesis"))
    default = load_suite(find_suite("default"))
    literals = [e.name for e in default.datasets if not e.is_pattern and not e.skip]
    for name in [*catalog.names(), *worlds.WORLDS, *literals]:
        theirs = default.options_for(name)
        if theirs is None:
            continue
        ours = thesis.options_for(name)
        assert ours is not None and ours.label == theirs.label, name
        assert ours.methods is not None and {"albot1:literal", "albot1:plus"} <= set(ours.methods), name
