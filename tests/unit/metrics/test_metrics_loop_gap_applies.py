"""A loop gap applies to a route that goes out and comes back, not to one that never left its start.

The rule was "the reference ends within 1 m (or 2 % of the route) of its start", which a robot parked, turning on
the spot or cut to its first scans also meets: ``odometry`` on ``synthetic-office-loop[:6]`` (0.5 m of straight
corridor) showed a loop gap, the drift of five steps, in the metrics table and on the thesis page. Such a route
must also travel as far as a revisit pair must (``MIN_TRAVEL_M``, 10 m).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.bench.grid import Cell
from albot1.data.open import open_sequence
from albot1.metrics.loop_gap import MIN_TRAVEL_M
from albot1.report.collect import METRIC_COLUMNS, CellRecord
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "cache"))


def _loop_gap_column(tmp_path: Path, dataset: str) -> tuple[float | None, str | None, float]:
    run_dir = write_run(run_method("odometry", open_sequence(dataset), dataset_name=dataset), tmp_path / "runs")
    metrics = evaluate_run(run_dir)
    cell = Cell("s", dataset, dataset, "odometry", "odometry", "default", "none", 0, "k", "v", 1, 1)
    record = CellRecord(cell, "done", run_dir, None, metrics, None)
    column = METRIC_COLUMNS["loop_gap_m"]
    drift = metrics.drift
    assert drift is not None
    return column.value(record), column.reason(record), drift.route_m


def test_a_route_that_never_leaves_its_start_has_no_loop_gap(tmp_path: Path) -> None:
    value, reason, route_m = _loop_gap_column(tmp_path, "synthetic-office-loop[:6]")
    assert route_m < 1.0  # ends within 1 m of its start: the old rule called this a closed loop
    assert value is None, f"a loop gap of {value} m on a route that never left its start"
    assert reason is not None and "never leaves its start" in reason and f"{MIN_TRAVEL_M:g} m" in reason
