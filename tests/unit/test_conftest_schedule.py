"""The order `make test` hands tests to its workers (``conftest.py``): longest first, module fixtures shared."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import DURATIONS_FILE, SLOW_DEFAULT_S, Unit, _durations, schedule_units


def test_modules_are_ordered_longest_first_and_ties_keep_the_collection_order() -> None:
    tests = [("a.py::t0", "a", False), ("b.py::t1", "b", False), ("c.py::t2", "c", False), ("d.py::t3", "d", False)]
    units = schedule_units(tests, {"b.py::t1": 100.0, "c.py::t2": 40.0, "d.py::t3": 40.0})
    assert [u.name for u in units] == ["b", "c", "d", "a"]
    assert [u.seconds for u in units] == [100.0, 40.0, 40.0, 0.0]


def test_a_module_is_one_unit_in_collection_order_estimated_as_the_sum_of_its_tests() -> None:
    tests = [("m.py::a", "m", False), ("x.py::long", "x", True), ("m.py::b", "m", True), ("x.py::short", "x", False)]
    units = schedule_units(tests, {"m.py::a": 30.0, "m.py::b": 25.0, "x.py::long": 50.0})
    assert units == [Unit("m", ("m.py::a", "m.py::b"), 55.0), Unit("x", ("x.py::long", "x.py::short"), 50.0)]


def test_a_slow_test_the_file_does_not_list_puts_its_module_before_the_quick_ones() -> None:
    tests = [("q.py::quick", "q", False), ("n.py::new_slow", "n", True), ("k.py::known", "k", True)]
    units = schedule_units(tests, {"k.py::known": 0.5})
    assert [(u.name, u.seconds) for u in units] == [("n", SLOW_DEFAULT_S), ("k", 0.5), ("q", 0.0)]


def test_the_collection_runs_in_that_order(request: pytest.FixtureRequest) -> None:
    """conftest's hook has reordered this session's items: every module's tests together, longest module first."""
    items = request.session.items
    modules = [item.module.__name__ for item in items if getattr(item, "module", None) is not None]
    seen = [m for i, m in enumerate(modules) if i == 0 or modules[i - 1] != m]
    assert len(seen) == len(set(seen)), "a module's tests are not together"
    tests = [(item.nodeid, item.module.__name__, item.get_closest_marker("slow") is not None) for item in items]
    assert [u.name for u in schedule_units(tests, _durations())] == seen


def test_the_durations_file_lists_seconds_of_tests_that_exist(request: pytest.FixtureRequest) -> None:
    """The committed file parses and names real test files (a renamed module would silently lose its place)."""
    durations = _durations()
    assert durations == json.loads(DURATIONS_FILE.read_text())
    assert durations and all(seconds > 0 for seconds in durations.values())
    root = Path(str(request.config.rootpath))
    missing = sorted({nodeid.split("::")[0] for nodeid in durations} - {p for p in _files(root)})
    assert not missing, f"{DURATIONS_FILE.name} names test files that do not exist: {missing}"


def _files(root: Path) -> set[str]:
    return {str(path.relative_to(root)) for path in (root / "tests").rglob("test_*.py")}
