"""Report tables: aggregation over seeds, formatting, and the split of accuracy and cost."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from albot1.bench.grid import Cell
from albot1.bench.store import Failure
from albot1.report.collect import COST_COLUMNS, METRIC_COLUMNS, CellRecord, dig
from albot1.report.tables import aggregate, cell_text, cells_frame, markdown, write_tables


def record(
    dataset: str, method: str, degradation: str, seed: int, ate: float | None, *, status: str = "done", ms: float = 1.0
) -> CellRecord:
    cell = Cell(
        suite="t",
        dataset=dataset,
        dataset_label=dataset,
        method=method,
        method_label=method,
        preset="default",
        degradation=degradation,
        seed=seed,
        key=f"{dataset}-{method}-{degradation}-{seed}",
        code_version="v",
        time_s=10,
        memory_mb=100,
    )
    if status != "done":
        return CellRecord(
            cell,
            status,
            Path("/nonexistent"),
            None,
            None,
            Failure("RuntimeError: boom", "exception", 2, 0.1, None) if status == "failed" else None,
        )
    metrics = {"ate": {"rmse_m": ate} if ate is not None else None, "updates": {"updates_per_view": 0.5}}
    result = {
        "scans": 10,
        "timing": {"per_scan_ms_median": ms, "per_scan_ms_p95": 2 * ms, "total_s": 0.01, "peak_mb": 100.0},
    }
    return CellRecord(cell, "done", Path("/nonexistent"), result, metrics, None)


def test_dig_follows_dotted_paths_and_rejects_non_numbers() -> None:
    data = {"a": {"b": 2, "c": None, "d": "x", "e": True}}
    assert dig(data, "a.b") == 2.0
    assert dig(data, "a.c") is None and dig(data, "a.d") is None and dig(data, "a.e") is None
    assert dig(data, "a.z.y") is None and dig(None, "a") is None


def test_aggregate_over_seeds_mean_median_min_max() -> None:
    records = [record("w", "odometry", "gauss:0.1:1", s, ate) for s, ate in ((0, 1.0), (1, 2.0), (2, 6.0))]
    records += [record("w", "odometry", "none", 0, 0.5), record("w", "odometry", "none", 1, None, status="failed")]
    table = aggregate(cells_frame(records), METRIC_COLUMNS)
    assert list(table["degradation"]) == ["none", "gauss:0.1:1"]  # by severity, whatever the plan order
    swept = table.iloc[1]
    assert swept["seeds"] == 3
    assert (swept["ate_rmse_m_mean"], swept["ate_rmse_m_median"], swept["ate_rmse_m_min"], swept["ate_rmse_m_max"]) == (
        3.0,
        2.0,
        1.0,
        6.0,
    )
    assert cell_text(swept, "ate_rmse_m") == "3.000 / 2.000 (1.000–6.000)"
    single = table.iloc[0]
    assert single["seeds"] == 1  # the failed seed is not averaged in
    assert cell_text(single, "ate_rmse_m") == "0.500"


def test_markdown_omits_columns_empty_for_a_dataset() -> None:
    records = [record("w", "odometry", "none", 0, None), record("v", "odometry", "none", 0, 0.25)]
    text = markdown(aggregate(cells_frame(records), METRIC_COLUMNS), METRIC_COLUMNS, "T")
    section_w = text.split("## w")[1].split("## v")[0]
    assert "ATE RMSE" not in section_w and "updates/view" in section_w
    assert "| odometry | none | 1 | 0.250 | 0.500 |" in text.split("## v")[1]


def test_write_tables_keeps_cost_out_of_the_accuracy_files(tmp_path: Path) -> None:
    records = [record("w", "odometry", "none", 0, 0.5, ms=3.0), record("w", "x", "none", 0, None, status="failed")]
    written = write_tables(records, tmp_path)
    metrics = pd.read_csv(written["metrics.csv"])
    cells = pd.read_csv(written["cells.csv"])
    cost = pd.read_csv(written["cost.csv"])
    assert not any(c.startswith(tuple(COST_COLUMNS)) for c in metrics.columns)
    assert not set(COST_COLUMNS) & set(cells.columns)
    assert cost.loc[0, "per_scan_ms_median_mean"] == 3.0
    assert list(cells["status"]) == ["done", "failed"] and cells.loc[1, "reason"] == "RuntimeError: boom"
