"""The order `make test` hands tests to its workers (``conftest.py``): longest first, module fixtures shared."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import DURATIONS_FILE, SLOW_DEFAULT_S, Unit, _durations, _uses_module_fixture, schedule_units


def test_units_are_ordered_longest_first_and_ties_keep_the_collection_order() -> None:
    tests = [(f"t.py::t{i}", "t", False, False) for i in range(5)]
    units = schedule_units(tests, {"t.py::t3": 40.0, "t.py::t1": 100.0, "t.py::t4": 40.0})
    assert [u.name for u in units] == ["t.py::t1", "t.py::t3", "t.py::t4", "t.py::t0", "t.py::t2"]
    assert [u.seconds for u in units] == [100.0, 40.0, 40.0, 0.0, 0.0]


def test_a_slow_test_the_file_does_not_list_goes_before_the_quick_ones() -> None:
    tests = [
        ("a.py::quick", "a", False, False),
        ("a.py::new_slow", "a", True, False),
        ("a.py::known", "a", True, False),
    ]
    units = schedule_units(tests, {"a.py::known": 0.5})
    assert units == [
        Unit("a.py::new_slow", ("a.py::new_slow",), SLOW_DEFAULT_S),
        Unit("a.py::known", ("a.py::known",), 0.5),
        Unit("a.py::quick", ("a.py::quick",), 0.0),
    ]


def test_a_module_sharing_a_module_fixture_is_one_unit_estimated_as_the_sum_of_its_tests() -> None:
    tests = [
        ("m.py::a", "m", False, True),
        ("x.py::long", "x", True, False),
        ("m.py::b", "m", True, True),
        ("x.py::short", "x", False, False),
    ]
    units = schedule_units(tests, {"m.py::a": 30.0, "m.py::b": 25.0, "x.py::long": 50.0})
    assert units == [
        Unit("m", ("m.py::a", "m.py::b"), 55.0),
        Unit("x.py::long", ("x.py::long",), 50.0),
        Unit("x.py::short", ("x.py::short",), 0.0),
    ]


@pytest.fixture(scope="module")
def shared_by_the_module() -> int:
    return 1


def test_a_test_using_a_module_fixture_is_seen_as_sharing_it(
    request: pytest.FixtureRequest, shared_by_the_module: int
) -> None:
    assert _uses_module_fixture(request.node)


def test_a_test_using_only_function_fixtures_is_not(request: pytest.FixtureRequest, tmp_path: Path) -> None:
    assert not _uses_module_fixture(request.node)


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
