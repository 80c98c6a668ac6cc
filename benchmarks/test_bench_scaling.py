"""How the grid's and the report's cost grow with the number of cells (recorded, never asserted).

A grid of cheap cells (dead reckoning on the first 20 views of a small synthetic world, one Gaussian
degradation, N seeds) is run through the real runner (``run_suite``: forkserver cell processes, 2 at a
time, each with its run folder, preview and metrics.json), then reported from scratch (tables, plots,
pages). Recorded per size, in ``extra_info``: the grid's wall seconds per cell and its overhead per cell
(the part of the 2 workers' time outside the cells' own attempts, ``attempt.json``); the CPU seconds per
cell of the process that plans, schedules and supervises the cells (the cells run in other processes:
this part grows with N if the runner does per-cell work over all cells); the cells' own mean wall and
their method's; the report's wall and CPU seconds per cell; the load average before and after (the wall
times mix growth with load on a shared machine, the CPU seconds much less). All should stay flat or fall
as N grows: a per-cell cost that grows with N is one a suite of thousands of cells pays quadratically.
Sizes 50 and 500 run in ``make bench-timing`` (about 1.5 min at load average 4);
``ALBOT1_SCALING_CELLS=5000`` adds a size, opt-in because it is long (its grid ~5-15 min on a quiet
machine, 34 min measured under load). Measured curve: ``docs/benchmarking.md``.
"""

from __future__ import annotations

import os
import resource
import time
from pathlib import Path
from typing import Any

import pytest

from albot1.bench.runner import run_suite
from albot1.report.collect import collect
from albot1.report.index import build_report

JOBS = 2
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


def _cpu_s(*, children: bool = True) -> float:
    """User + system CPU seconds of this process and (``children``) of its ended children (the report's workers)."""
    usage = [resource.getrusage(resource.RUSAGE_SELF)]
    usage += [resource.getrusage(resource.RUSAGE_CHILDREN)] if children else []
    return sum(u.ru_utime + u.ru_stime for u in usage)


def _cells(root: Path) -> dict[str, float]:
    """Mean wall seconds of the cells' own attempts and of their method's run, over the completed cells."""
    _, records = collect(root)
    attempts = [r.attempt.elapsed_s for r in records if r.attempt is not None]
    methods = [r.result.timing.wall_s for r in records if r.result is not None]
    return {"cell_s": sum(attempts) / len(attempts), "method_s": sum(methods) / len(methods)}


@pytest.mark.slow
@pytest.mark.parametrize("cells", SIZES)
def test_grid_and_report_cost_per_cell(benchmark: Any, tmp_path: Path, cells: int) -> None:
    suite = _suite(tmp_path / f"scaling{cells}.toml", cells)
    timings: dict[str, float] = {"load_before": os.getloadavg()[0]}

    def grid_then_report() -> None:
        start, cpu = time.perf_counter(), _cpu_s(children=False)
        _, summary, store = run_suite(str(suite), results=tmp_path / "results", jobs=JOBS)
        timings["grid_s"], timings["runner_cpu_s"] = time.perf_counter() - start, _cpu_s(children=False) - cpu
        assert summary.counts["done"] == cells, summary.counts
        start, cpu = time.perf_counter(), _cpu_s()
        build_report(store.root, tmp_path / "report", jobs=JOBS)
        timings["report_s"], timings["report_cpu_s"] = time.perf_counter() - start, _cpu_s() - cpu
        timings.update(_cells(store.root))

    benchmark.pedantic(grid_then_report, rounds=1, iterations=1)
    benchmark.extra_info.update(
        cells=cells,
        grid_s=timings["grid_s"],
        report_s=timings["report_s"],
        report_cpu_s=timings["report_cpu_s"],
        grid_s_per_cell=timings["grid_s"] / cells,
        overhead_s_per_cell=timings["grid_s"] * JOBS / cells - timings["cell_s"],
        runner_cpu_s_per_cell=timings["runner_cpu_s"] / cells,
        cell_s=timings["cell_s"],
        method_s=timings["method_s"],
        report_s_per_cell=timings["report_s"] / cells,
        report_cpu_s_per_cell=timings["report_cpu_s"] / cells,
        load_before=timings["load_before"],
        load_after=os.getloadavg()[0],
    )
