"""Timing of the benchmark runner itself (recorded by pytest-benchmark, never asserted).

* per-cell overhead: one dead-reckoning cell on the 106-view synthetic world
  through the full path (child process from the forkserver, run, run folder,
  preview, metrics.json), minus nothing -- the method's own work is tiny, so
  this is what every cell of a grid pays on top of its method;
* the report: tables and plots of a small results folder.
"""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import pytest

from albot1.bench.cells import renderer_target
from albot1.bench.grid import Cell
from albot1.bench.job import run_cell_job
from albot1.bench.plan import plan_suite
from albot1.bench.store import ResultsStore
from albot1.bench.suite import parse_suite
from albot1.report.index import build_report
from albot1.report.preview import render_preview
from albot1.settings import get_settings

SUITE = {
    "grid": {"degradations": ["gauss:0.1:1"], "seeds": [0, 1]},
    "methods": [{"name": "odometry"}],
    "datasets": [{"name": "synthetic-office-startstop"}],
}
PREVIEW = renderer_target(render_preview)  # as `albot1 bench` draws it


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory) -> tuple[ResultsStore, list[Cell]]:
    plan = plan_suite(parse_suite(SUITE, name="timing", source="test_bench_runner"), get_settings())
    store = ResultsStore(tmp_path_factory.mktemp("results") / "timing")
    store.write_plan(plan)
    return store, plan.cells


def test_per_cell_overhead(benchmark: Any, planned: tuple[ResultsStore, list[Cell]]) -> None:
    store, cells = planned
    cell = cells[0]
    run_cell_job(cell, str(store.root), PREVIEW)  # starts the forkserver once, as a grid does

    def fresh() -> tuple[tuple[Cell, str, str], dict[str, Any]]:
        shutil.rmtree(store.run_dir(cell.key), ignore_errors=True)
        return (cell, str(store.root), PREVIEW), {}

    outcome = benchmark.pedantic(run_cell_job, setup=fresh, rounds=5, iterations=1)
    assert outcome.status == "done", outcome.reason


def test_report_build(benchmark: Any, planned: tuple[ResultsStore, list[Cell]], tmp_path: Path) -> None:
    store, cells = planned
    for cell in cells:
        if not store.is_complete(cell.key):
            assert run_cell_job(cell, str(store.root), PREVIEW).status == "done"
    index = benchmark.pedantic(build_report, args=(store.root, tmp_path / "report"), rounds=2, iterations=1)
    assert index.is_file()
