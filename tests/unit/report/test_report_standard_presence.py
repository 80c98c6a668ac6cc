"""The standard-benchmark page is written only for a suite that touches one of the five logs.

A suite of a user's own bags would otherwise get a page of five "not
measured" logs linked from its report: a page with nothing to show.
"""

from __future__ import annotations

from pathlib import Path

from albot1.bench.grid import Cell, GridPlan, Skipped
from albot1.report.collect import CellRecord
from albot1.report.standard import on_standard_logs


def _record(label: str) -> CellRecord:
    cell = Cell(
        suite="t",
        dataset=label,
        dataset_label=label,
        method="odometry",
        method_label="odometry",
        preset="default",
        degradation="none",
        seed=0,
        key="k",
        code_version="v",
        time_s=60.0,
        memory_mb=1024.0,
    )
    return CellRecord(cell, "not run", Path("k"), None, None, None)


def _plan(skipped: list[Skipped]) -> GridPlan:
    return GridPlan("t", None, "", [], skipped, [], {}, [0], ["none"], {"platform": "test"})


def test_only_a_suite_on_a_standard_log_gets_the_page() -> None:
    own = _record("robot.mcap?reference=gt.tum")
    assert not on_standard_logs(_plan([]), [own])
    assert on_standard_logs(_plan([]), [own, _record("mit-csail")])
    assert not on_standard_logs(_plan([]), [_record("aces[:500]")])  # a prefix is never a standard row either
    # skipped for want of data: the page says how to fetch it
    assert on_standard_logs(_plan([Skipped("aces", "not found", "albot1 datasets fetch aces")]), [own])
    assert not on_standard_logs(_plan([Skipped("seattle-corrected", "not found", "")]), [own])
