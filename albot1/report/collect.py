"""Read a results folder (``results/<suite>``) into one row per planned cell.

Only the cells of the folder's ``grid.json`` (the last `albot1 bench` plan)
are read: run folders left from older code versions stay on disk but never
mix into a report. Each row carries the cell's coordinates, its status
(done, failed, or not run -- the runner was stopped before it), and the
numbers the tables use, taken from ``metrics.json`` and ``result.json`` by
the dotted paths in :data:`METRIC_COLUMNS` and :data:`COST_COLUMNS`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from albot1.bench.grid import Cell, GridPlan
from albot1.bench.store import ATTEMPT, METRICS, Failure, ResultsStore

if TYPE_CHECKING:
    from albot1.runs.folder import StoredRun

#: column -> (source file, dotted path, header text); accuracy numbers, identical for identical inputs
METRIC_COLUMNS: dict[str, tuple[str, str, str]] = {
    "ate_rmse_m": ("metrics", "ate.rmse_m", "ATE RMSE (m)"),
    "loop_gap_m": ("metrics", "loop_gap.route.gap_m", "loop gap (m)"),
    "revisit_gap_m": ("metrics", "loop_gap.translation_m.mean", "revisit gap mean (m)"),
    "orientation_deg": ("metrics", "orientation.bearing_abs_error_mean_deg", "bearing error mean (deg)"),
    "relation_m": ("metrics", "relations.translation_m.mean", "relation trans. (m)"),
    "relation_deg": ("metrics", "relations.rotation_deg.mean", "relation rot. (deg)"),
    "map_precision": ("metrics", "map_shape.precision", "map precision"),
    "map_coverage": ("metrics", "map_shape.coverage", "map coverage"),
    "updates_per_view": ("metrics", "updates.updates_per_view", "updates/view"),
}
#: cost numbers: they vary from run to run and machine to machine, so they live in their own table
COST_COLUMNS: dict[str, tuple[str, str, str]] = {
    "per_scan_ms_median": ("result", "timing.per_scan_ms_median", "per-scan median (ms)"),
    "per_scan_ms_p95": ("result", "timing.per_scan_ms_p95", "per-scan p95 (ms)"),
    "total_s": ("result", "timing.total_s", "total (s)"),
    "peak_mb": ("result", "timing.peak_mb", "peak (MB)"),
    "cell_s": ("attempt", "elapsed_s", "cell wall (s)"),
}
KEY_COLUMNS = ("dataset", "method", "degradation")


@dataclass
class CellRecord:
    """One planned cell and what the store holds for it."""

    cell: Cell
    status: str  # done | failed | not run
    run_dir: Path
    result: dict[str, Any] | None
    metrics: dict[str, Any] | None
    failure: Failure | None
    attempt: dict[str, Any] | None = None
    _stored: StoredRun | None = field(default=None, repr=False, compare=False)

    def stored_run(self) -> StoredRun:
        """The run folder read back, once per record (several plots draw the same run)."""
        if self._stored is None:
            from albot1.runs.folder import read_run

            self._stored = read_run(self.run_dir)
        return self._stored


def dig(data: dict[str, Any] | None, path: str) -> float | None:
    """``data["a"]["b"]`` for ``"a.b"``; None when absent or not a number."""
    current: Any = data
    for part in path.split("."):
        if not isinstance(current, dict) or part not in current:
            return None
        current = current[part]
    if isinstance(current, bool) or not isinstance(current, (int, float)):
        return None
    return float(current)


def collect(results_dir: str | Path) -> tuple[GridPlan, list[CellRecord]]:
    """The plan of ``results_dir`` and a record per planned cell (suite order)."""
    store = ResultsStore(results_dir)
    plan = store.read_plan()
    records: list[CellRecord] = []
    for cell in plan.cells:
        run_dir = store.run_dir(cell.key)
        if store.is_complete(cell.key):
            records.append(
                CellRecord(
                    cell,
                    "done",
                    run_dir,
                    store.read_json(cell.key, "result.json"),
                    store.read_json(cell.key, METRICS),
                    None,
                    store.read_json(cell.key, ATTEMPT),
                )
            )
            continue
        failure = store.failure(cell.key)
        records.append(CellRecord(cell, "failed" if failure else "not run", run_dir, None, None, failure))
    return plan, records


def cell_rows(records: list[CellRecord]) -> list[dict[str, Any]]:
    """Flat rows (one per cell) with coordinates, status and every metric and cost column."""
    rows = []
    for rec in records:
        c = rec.cell
        row: dict[str, Any] = {
            "dataset": c.dataset_label,
            "method": c.method_label,
            "degradation": c.degradation,
            "seed": c.seed,
            "status": rec.status,
            "key": c.key,
            "scans": (rec.result or {}).get("scans"),
        }
        sources = {"metrics": rec.metrics, "result": rec.result, "attempt": rec.attempt}
        for column, (source, path, _) in {**METRIC_COLUMNS, **COST_COLUMNS}.items():
            row[column] = dig(sources[source], path)
        row["reason"] = rec.failure.reason if rec.failure else None
        rows.append(row)
    return rows


def severity_order(levels: list[str]) -> list[str]:
    """none, then Gaussian levels by sigma, then biases, then the thesis's systematic degradation."""
    from albot1.data.degrade import parse_spec

    rank = {"none": 0, "gauss": 1, "bias": 2, "thesis": 3}

    def key(level: str) -> tuple[int, float, float]:
        spec = parse_spec(level)
        return rank.get(spec.kind, 4), spec.a, spec.b

    return sorted(levels, key=key)
