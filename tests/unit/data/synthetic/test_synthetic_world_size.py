"""A world too large to generate is one line, not numpy's ArrayMemoryError (out49's selector sweep)."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.bench.errors import SuiteError
from albot1.bench.plan import plan_suite
from albot1.bench.suite import load_suite
from albot1.data.open import open_sequence
from albot1.data.synthetic.errors import WorldOptionError
from albot1.data.synthetic.generate import MAX_WORLD_SCANS
from albot1.settings import Settings

HUGE = "synthetic-office-loop?laps=999999999"


def test_too_many_laps_are_refused_before_any_array_is_built() -> None:
    """Old code: `?laps=999999999` asked numpy for 40.8 TiB (a traceback)."""
    with pytest.raises(WorldOptionError) as caught:
        open_sequence(f"{HUGE}[:5]")
    assert str(caught.value) == (
        f"synthetic world {HUGE!r}: 999999999 laps of 1870 scans would be 1,869,999,998,131 scans; "
        f"expected at most {MAX_WORLD_SCANS:,} (a world is generated whole, in memory): give fewer laps"
    )


def test_a_suite_naming_such_a_world_stops_with_one_line(tmp_path: Path) -> None:
    suite = tmp_path / "huge.toml"
    suite.write_text(f'[[methods]]\nname = "odometry"\n[[datasets]]\nname = "{HUGE}[:5]"\n')
    with pytest.raises(SuiteError) as caught:
        plan_suite(load_suite(suite), Settings(data_dir=None, cache_dir=tmp_path / "cache"))
    assert "999999999 laps of 1870 scans" in str(caught.value) and "\n" not in str(caught.value)


def test_the_largest_embedded_world_is_far_inside_the_bound() -> None:
    assert open_sequence("synthetic-office-long").known_scan_count == 37401 < MAX_WORLD_SCANS // 50
