"""A dataset entry's `methods`: only the named method entries run on it; a label that names none is an error."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.bench.errors import SuiteError
from albot1.bench.plan import plan_suite
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
