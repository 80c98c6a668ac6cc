"""Report plot helpers: ordering of degradation levels, file names, the representative run."""

from __future__ import annotations

from pathlib import Path

from albot1.bench.grid import Cell
from albot1.report.collect import CellRecord, severity_order
from albot1.report.plots import representative, slug


def test_severity_order_puts_none_first_then_gaussian_by_sigma_then_thesis() -> None:
    levels = ["thesis", "gauss:0.2:3", "none", "bias:0.01:0.1", "gauss:0.05:0.5", "gauss:0.1:1"]
    assert severity_order(levels) == ["none", "gauss:0.05:0.5", "gauss:0.1:1", "gauss:0.2:3", "bias:0.01:0.1", "thesis"]


def test_slug_makes_dataset_labels_file_safe() -> None:
    assert slug("aces[:2500:2]") == "aces_2500_2"
    assert slug("/data/my log.clf") == "data_my_log.clf"


def _record(method: str, degradation: str, seed: int, status: str = "done") -> CellRecord:
    cell = Cell(
        suite="t",
        dataset="w",
        dataset_label="w",
        method=method,
        method_label=method,
        preset="default",
        degradation=degradation,
        seed=seed,
        key=f"{method}{degradation}{seed}",
        code_version="v",
        time_s=1,
        memory_mb=1,
    )
    return CellRecord(cell, status, Path("/x"), None, None, None)


def test_representative_run_is_the_undegraded_lowest_seed_that_completed() -> None:
    records = [
        _record("a", "gauss:0.1:1", 0),
        _record("a", "none", 1),
        _record("a", "none", 0, status="failed"),
        _record("b", "gauss:0.1:1", 2),
        _record("b", "gauss:0.1:1", 1),
    ]
    chosen = representative(records)
    assert (chosen["a"].cell.degradation, chosen["a"].cell.seed) == ("none", 1)
    assert (chosen["b"].cell.degradation, chosen["b"].cell.seed) == ("gauss:0.1:1", 1)
