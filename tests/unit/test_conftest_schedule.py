"""The order `make test` hands tests to its workers (``conftest.py``): longest first, module fixtures shared."""

from __future__ import annotations

import gc
import json
from pathlib import Path

import pytest

from conftest import DURATIONS_FILE, SLOW_DEFAULT_S, Unit, _durations, _shares_state, schedule_units


def test_modules_are_ordered_longest_first_and_ties_keep_the_collection_order() -> None:
    tests = [(f"{m}.py::t{i}", m, False, False) for i, m in enumerate("abcd")]
    units = schedule_units(tests, {"b.py::t1": 100.0, "c.py::t2": 40.0, "d.py::t3": 40.0})
    assert [u.name for u in units] == ["b", "c", "d", "a"]
    assert [u.seconds for u in units] == [100.0, 40.0, 40.0, 0.0]


def test_a_module_is_one_unit_estimated_as_the_sum_of_its_tests_its_longest_test_first() -> None:
    tests = [
        ("m.py::a", "m", False, False),
        ("x.py::short", "x", False, False),
        ("m.py::b", "m", True, False),
        ("x.py::long", "x", True, False),
        ("m.py::c", "m", False, False),
        ("m.py::d", "m", False, False),
    ]
    units = schedule_units(tests, {"m.py::a": 25.0, "m.py::b": 30.0, "x.py::long": 50.0})
    assert units == [
        Unit("m", ("m.py::b", "m.py::a", "m.py::c", "m.py::d"), 55.0),
        Unit("x", ("x.py::long", "x.py::short"), 50.0),
    ]


def test_a_module_whose_tests_share_state_keeps_its_order() -> None:
    tests = [("r.py::part1", "r", True, True), ("r.py::part2", "r", True, False), ("r.py::other", "r", False, False)]
    units = schedule_units(tests, {"r.py::part1": 70.0, "r.py::part2": 120.0})
    assert units == [Unit("r", ("r.py::part1", "r.py::part2", "r.py::other"), 190.0)]


def test_a_slow_test_the_file_does_not_list_puts_its_module_before_the_quick_ones() -> None:
    tests = [
        ("q.py::quick", "q", False, False),
        ("n.py::new_slow", "n", True, False),
        ("k.py::known", "k", True, False),
    ]
    units = schedule_units(tests, {"k.py::known": 0.5})
    assert [(u.name, u.seconds) for u in units] == [("n", SLOW_DEFAULT_S), ("k", 0.5), ("q", 0.0)]


@pytest.fixture(scope="module")
def shared_by_the_module() -> int:
    return 1


def test_a_test_using_a_module_fixture_shares_state(request: pytest.FixtureRequest, shared_by_the_module: int) -> None:
    assert _shares_state(request.node)


def test_a_test_using_only_function_fixtures_does_not(request: pytest.FixtureRequest, tmp_path: Path) -> None:
    assert not _shares_state(request.node)


def test_the_session_runs_in_that_order(request: pytest.FixtureRequest) -> None:
    """conftest's hook has reordered this session's items: every module's tests together, longest module first."""
    items = request.session.items
    modules = [item.module.__name__ for item in items if getattr(item, "module", None) is not None]
    seen = [m for i, m in enumerate(modules) if i == 0 or modules[i - 1] != m]
    assert len(seen) == len(set(seen)), "a module's tests are not together"
    tests = [(i.nodeid, i.module.__name__, i.get_closest_marker("slow") is not None, _shares_state(i)) for i in items]
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


def test_the_garbage_collector_paused_for_collection_is_on_again_for_the_tests() -> None:
    """``conftest.pytest_collection`` pauses the cyclic collector while collecting and must resume it."""
    assert gc.isenabled()


def test_the_root_conftest_is_the_only_one() -> None:
    """Tests import helpers with ``from conftest import ...``: a second conftest.py (tests/unit/data/conftest.py did,
    for one fixture) can be the module named ``conftest`` when they are collected, and they fail to import."""
    root = Path(__file__).resolve().parents[2]
    found = sorted(str(p.relative_to(root)) for p in (root / "tests").rglob("conftest.py"))
    found += sorted(str(p.relative_to(root)) for p in (root / "benchmarks").rglob("conftest.py"))
    assert found == [], found


def test_a_module_s_estimate_does_not_depend_on_the_order_of_its_tests() -> None:
    """1.1 + 1.5 + 1.2 is 3.8000000000000003 in collection order and 3.8 longest first: a tie with a 3.8 module flipped.

    The session's order is worked out from the collection order, and the check of it above from the reordered
    items (each module longest test first): a float sum made the two disagree (seen in a full `make test`).
    """
    durations = {"a.py::t1": 1.1, "a.py::t2": 1.5, "a.py::t3": 1.2, "b.py::t": 3.8}
    tests = [(n, n.split("::")[0], False, False) for n in ("b.py::t", "a.py::t1", "a.py::t2", "a.py::t3")]
    units = schedule_units(tests, durations)
    reordered = [(n, u.name, False, False) for u in units for n in u.nodeids]
    assert [u.name for u in schedule_units(reordered, durations)] == [u.name for u in units] == ["b.py", "a.py"]
