"""`make test-fast` is chosen by measured cost (``conftest.py``): a test the durations file lists is not in it.

Before (issue 24), the lane left out only the hand-set ``slow`` marks and ran every property test at its own
example count: 2,978 tests, ~285 CPU-s, 2.5 min at best on 2 cores for a loop meant to take under a minute.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import conftest
from conftest import FAST_MAX_EXAMPLES, FAST_MAX_S, FAST_PROFILE, pytest_itemcollected


@dataclass
class _Item:
    """What ``pytest_itemcollected`` reads of a collected test, and the markers it adds."""

    nodeid: str
    obj: Any = None
    fixturenames: tuple[str, ...] = ()
    markers: list[str] = field(default_factory=list)

    def add_marker(self, marker: pytest.MarkDecorator) -> None:
        self.markers.append(marker.name)


@pytest.fixture
def profile() -> Iterator[None]:
    """The hypothesis profile this process had, loaded again after the test."""
    before = settings.get_current_profile_name()
    yield
    settings.load_profile(before)


@pytest.fixture
def recorded(monkeypatch: pytest.MonkeyPatch) -> dict[str, float]:
    """The durations file the hook reads, replaced by one the test writes."""
    durations: dict[str, float] = {}
    monkeypatch.setattr(conftest, "_durations", lambda: durations)
    return durations


def test_a_test_recorded_at_the_bound_or_over_is_marked_slow_and_the_others_are_not(
    recorded: dict[str, float], profile: None
) -> None:
    settings.load_profile("default")
    recorded.update({"t.py::long": 30.0, "t.py::at": FAST_MAX_S, "t.py::quick": FAST_MAX_S / 2})
    items = [_Item(name) for name in ("t.py::long", "t.py::at", "t.py::quick", "t.py::new_since_the_file")]
    for item in items:
        pytest_itemcollected(item)  # type: ignore[arg-type]
    assert [item.markers for item in items] == [["slow"], ["slow"], [], []]


def _counting_property(calls: list[int]) -> Any:
    @settings(max_examples=500, deadline=None, database=None)
    @given(st.integers())
    def prop(x: int) -> None:
        calls.append(x)

    return prop


def test_the_fast_profile_keeps_a_recorded_property_test_and_caps_its_examples(
    recorded: dict[str, float], profile: None
) -> None:
    calls: list[int] = []
    item = _Item("p.py::prop", _counting_property(calls))
    recorded[item.nodeid] = 10 * FAST_MAX_S
    settings.load_profile(FAST_PROFILE)
    pytest_itemcollected(item)  # type: ignore[arg-type]
    assert item.markers == []  # its recorded seconds were for 500 examples
    item.obj()
    assert 1 <= len(calls) <= FAST_MAX_EXAMPLES


def test_the_default_profile_runs_a_property_test_s_own_count_and_its_record_marks_it_slow(
    recorded: dict[str, float], profile: None
) -> None:
    calls: list[int] = []
    item = _Item("p.py::prop", _counting_property(calls))
    recorded[item.nodeid] = 10 * FAST_MAX_S
    settings.load_profile("default")
    pytest_itemcollected(item)  # type: ignore[arg-type]
    assert item.markers == ["slow"]
    item.obj()
    assert len(calls) > FAST_MAX_EXAMPLES  # make test's count: up to 500 (hypothesis stops early on few values)


def test_this_session_marks_every_test_the_file_lists_slow_but_under_the_fast_profile_the_property_tests(
    request: pytest.FixtureRequest,
) -> None:
    """The rule holds for the session's own items (whatever ``-m`` selected, each was marked before selection)."""
    fast = settings.get_current_profile_name() == FAST_PROFILE
    durations = conftest._durations()
    for item in request.session.items:
        if durations.get(item.nodeid, 0.0) >= FAST_MAX_S and not (fast and conftest._hypothesis_test(item)):
            assert item.get_closest_marker("slow") is not None, item.nodeid
