"""A run planned twice under one label is one row of its table group, not two.

Two spellings of one slice in a suite (``NAME[:30]`` and ``NAME[0:30]``) plan the same cells twice with one
key, one run folder and one label (albot1.bench.plan). The report took every planned copy as a row of its group:
the mean stayed, but the std, the median and the ``planned`` count were those of each seed counted twice.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.bench.cells import execute_cell
from albot1.bench.plan import plan_suite
from albot1.bench.store import ResultsStore
from albot1.bench.suite import parse_suite
from albot1.report.collect import collect
from albot1.report.tables import Aggregates
from albot1.settings import get_settings

WORLD = "synthetic-corridor"


@pytest.fixture(scope="module")
def results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    data = {
        "grid": {"degradations": ["gauss:0.05:1"], "seeds": [0, 1], "undegraded_seeds": [0]},
        "methods": [{"name": "odometry"}],
        "datasets": [{"name": f"{WORLD}[:30]"}, {"name": f"{WORLD}[0:30]"}],
    }
    plan = plan_suite(parse_suite(data, name="twice", source="twice.toml"), get_settings())
    assert len(plan.cells) == 6 and len({c.key for c in plan.cells}) == 3  # the premise: each run planned twice
    root = tmp_path_factory.mktemp("results") / "twice"
    store = ResultsStore(root)
    store.write_plan(plan)
    done: set[str] = set()
    for cell in plan.cells:
        if cell.key not in done:  # the runner computes a shared key once
            execute_cell(cell, store.runs)
            done.add(cell.key)
    return root


def test_a_run_planned_twice_is_one_record_and_its_seeds_are_counted_once(results: Path) -> None:
    _, records = collect(results)
    assert len(records) == 3 and all(r.status == "done" for r in records)
    table = Aggregates(records).metrics
    [row] = table[table["degradation"] == "gauss:0.05:1"].to_dict("records")
    ates = [r.metrics.ate.rmse_m for r in records if r.cell.degradation == "gauss:0.05:1"]
    assert row["seeds"] == 2 and row["planned"] == 2
    assert row["ate_rmse_m_std"] == pytest.approx(np.std(ates, ddof=1), rel=1e-12)
