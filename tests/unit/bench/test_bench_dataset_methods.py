"""Which method entries run on which datasets (a dataset entry's `methods`, a method entry's `datasets`), and
`allow_failure`."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.bench.errors import SuiteError
from albot1.bench.grid import Cell, CellOutcome
from albot1.bench.plan import plan_suite
from albot1.bench.runner import kept_failure
from albot1.bench.store import ResultsStore
from albot1.bench.suite import load_suite
from albot1.settings import Settings

SUITE = """
[[methods]]
name = "odometry"

[[methods]]
name = "albot1"
preset = "thesis"

[[methods]]
name = "albot1"
preset = "literal"

[[datasets]]
name = "synthetic-office-startstop"

[[datasets]]
name = "synthetic-corridor"
methods = ["albot1:literal"]
"""


def _plan(tmp_path: Path, text: str) -> list[tuple[str, str]]:
    path = tmp_path / "tiny.toml"
    path.write_text(text)
    plan = plan_suite(load_suite(path), Settings(data_dir=None, cache_dir=tmp_path / "cache"))
    return sorted((c.dataset_label, c.method_label) for c in plan.cells)


def test_only_the_listed_methods_run_on_the_entry_and_every_method_elsewhere(tmp_path: Path) -> None:
    assert _plan(tmp_path, SUITE) == [
        ("synthetic-corridor", "albot1:literal"),
        ("synthetic-office-startstop", "albot1:literal"),
        ("synthetic-office-startstop", "albot1:thesis"),
        ("synthetic-office-startstop", "odometry"),
    ]


def test_a_later_entry_replaces_the_method_list_of_an_earlier_glob(tmp_path: Path) -> None:
    text = SUITE.replace('name = "synthetic-office-startstop"', 'name = "synthetic-office-*"\nmethods = ["odometry"]')
    text += '\n[[datasets]]\nname = "synthetic-office-startstop"\nmethods = ["albot1:thesis", "odometry"]\n'
    text += '\n[[datasets]]\nname = "synthetic-office-long"\nskip = true\n'
    cells = _plan(tmp_path, text)
    assert ("synthetic-office-startstop", "albot1:thesis") in cells
    assert ("synthetic-office-loop", "odometry") in cells
    assert not [c for c in cells if c[0] == "synthetic-office-loop" and c[1] != "odometry"]


def test_a_method_label_that_names_no_method_entry_is_an_error_of_the_suite(tmp_path: Path) -> None:
    path = tmp_path / "tiny.toml"
    path.write_text(SUITE.replace('methods = ["albot1:literal"]', 'methods = ["albot1:plus"]'))
    with pytest.raises(SuiteError) as caught:
        load_suite(path)
    message = str(caught.value)
    assert str(path) in message and "'albot1:plus' name no method entry" in message
    assert "'albot1:thesis'" in message  # the labels that exist


def test_a_method_entrys_datasets_restrict_it_to_the_datasets_its_globs_match(tmp_path: Path) -> None:
    text = SUITE.replace(
        'name = "albot1"\npreset = "thesis"', 'name = "albot1"\npreset = "thesis"\ndatasets = ["*-corridor"]'
    )
    assert _plan(tmp_path, text) == [
        ("synthetic-corridor", "albot1:literal"),
        ("synthetic-office-startstop", "albot1:literal"),
        ("synthetic-office-startstop", "odometry"),
    ]  # albot1:thesis is on no dataset: the corridor entry lists albot1:literal only


def test_a_method_entrys_datasets_glob_that_matches_no_dataset_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "tiny.toml"
    path.write_text(SUITE.replace('name = "odometry"', 'name = "odometry"\ndatasets = ["no-such-log*"]'))
    with pytest.raises(SuiteError) as caught:
        plan_suite(load_suite(path), Settings(data_dir=None, cache_dir=tmp_path / "cache"))
    assert "method entry 'odometry': datasets pattern 'no-such-log*' matches no dataset" in str(caught.value)


def test_allow_failure_reaches_the_cells_and_allows_only_the_methods_own_failures(tmp_path: Path) -> None:
    odometry, other = _allowed_and_not(tmp_path)
    assert odometry.allow_failure and not other.allow_failure
    for kind in ("exception", "memory", "timeout", "crash"):
        assert CellOutcome.of(odometry, "failed", 1.0, "x", kind).allowed  # type: ignore[arg-type]
        assert not CellOutcome.of(other, "failed", 1.0, "x", kind).allowed  # type: ignore[arg-type]
    for kind in ("config", "executor", "interrupted", "storage"):
        assert not CellOutcome.of(odometry, "failed", 1.0, "x", kind).allowed  # type: ignore[arg-type]
    assert not CellOutcome.of(odometry, "done", 1.0).allowed
    # Not part of the run's identity: allowing a failure changes no result.
    assert odometry.key == next(
        c.key
        for c in plan_suite(
            load_suite(_write(tmp_path, SUITE)), Settings(data_dir=None, cache_dir=tmp_path / "c")
        ).cells
        if c.method_label == "odometry" and c.dataset_label == odometry.dataset_label
    )


def _allowed_and_not(tmp_path: Path) -> tuple[Cell, Cell]:
    """A cell of odometry, whose entry says allow_failure, and a cell of another method."""
    path = tmp_path / "tiny.toml"
    path.write_text(SUITE.replace('name = "odometry"', 'name = "odometry"\nallow_failure = true'))
    plan = plan_suite(load_suite(path), Settings(data_dir=None, cache_dir=tmp_path / "cache"))
    odometry = next(c for c in plan.cells if c.method_label == "odometry")
    return odometry, next(c for c in plan.cells if c.method_label != "odometry")


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "plain.toml"
    path.write_text(text)
    return path


def test_only_an_allowed_methods_own_error_is_kept_from_an_earlier_run(tmp_path: Path) -> None:
    """The same key fails the same way only for the method's own error; limits and crashes depend on the load."""
    odometry, other = _allowed_and_not(tmp_path)
    store = ResultsStore(tmp_path / "store")
    for cell in (odometry, other):
        store.prepare(cell)
        assert kept_failure(store, cell) is None  # nothing recorded: run it
    store.record_failure(other, "diverged", "exception")
    assert kept_failure(store, other) is None  # not allowed by the suite: always retried
    for kind in ("timeout", "memory", "crash", "executor", "storage", "interrupted"):
        store.record_failure(odometry, f"a {kind}", kind)  # type: ignore[arg-type]
        assert kept_failure(store, odometry) is None, kind
    store.record_failure(odometry, "diverged at scan 7", "exception", elapsed_s=12.5)
    kept = kept_failure(store, odometry)
    assert kept is not None and kept.kept and kept.allowed and kept.status == "failed"
    assert (kept.key, kept.kind, kept.reason) == (odometry.key, "exception", "diverged at scan 7")
    assert kept.elapsed_s == 0.0  # no time spent in this run: the summary's cell-seconds are this run's
    (store.run_dir(odometry.key) / "FAILED.json").write_text("{not json")
    assert kept_failure(store, odometry) is None  # an unreadable record is never trusted
