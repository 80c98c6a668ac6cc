"""How the grid's and the report's cost grow with the number of cells (recorded, never asserted).

A grid of cheap cells (dead reckoning on the first 20 views of a small synthetic world, one Gaussian
degradation, N seeds) is run through the real runner (``run_suite``: forkserver cell processes, 2 at a
time, each with its run folder, preview and metrics.json), then reported (tables, plots, pages). What is
recorded per size, in ``extra_info``: wall seconds per cell of the grid and of the report. Both should
stay flat as N grows: a per-cell cost that grows with N is a cost that a suite of thousands of cells pays
quadratically. Sizes 50 and 500 run in ``make bench-timing``; ``ALBOT1_SCALING_CELLS=5000`` adds a size
(about 17 minutes on two cores). Measured curve: ``docs/benchmarking.md``.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

import pytest

from albot1.bench.runner import run_suite
from albot1.report.index import build_report

SIZES = [50, 500, *([int(os.environ["ALBOT1_SCALING_CELLS"])] if os.environ.get("ALBOT1_SCALING_CELLS") else [])]


def _suite(path: Path, cells: int) -> Path:
    seeds = ", ".join(str(s) for s in range(cells))
    path.write_text(
        f'description = "scaling: {cells} cheap cells"\n'
        f'[grid]\ndegradations = ["gauss:0.05:1"]\nseeds = [{seeds}]\nundegraded_seeds = []\n'
        '[[methods]]\nname = "odometry"\n'
        '[[datasets]]\nname = "synthetic-office-startstop[:20]"\n',
        encoding="utf-8",
    )
    return path


@pytest.mark.slow
@pytest.mark.parametrize("cells", SIZES)
def test_grid_and_report_cost_per_cell(benchmark: Any, tmp_path: Path, cells: int) -> None:
    suite = _suite(tmp_path / f"scaling{cells}.toml", cells)
    timings: dict[str, float] = {}

    def grid_then_report() -> None:
        start = time.perf_counter()
        _, summary, store = run_suite(str(suite), results=tmp_path / "results", jobs=2)
        timings["grid_s"] = time.perf_counter() - start
        assert summary.counts["done"] == cells, summary.counts
        start = time.perf_counter()
        build_report(store.root, tmp_path / "report", jobs=2)
        timings["report_s"] = time.perf_counter() - start

    benchmark.pedantic(grid_then_report, rounds=1, iterations=1)
    benchmark.extra_info.update(
        cells=cells,
        grid_s=timings["grid_s"],
        report_s=timings["report_s"],
        grid_s_per_cell=timings["grid_s"] / cells,
        report_s_per_cell=timings["report_s"] / cells,
    )
