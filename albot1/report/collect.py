"""Read a results folder (``results/<suite>``) into one row per planned cell.

Only the cells of the folder's ``grid.json`` (the last `albot1 bench` plan)
are read: run folders left from older code versions stay on disk but never
mix into a report. Each row carries the cell's coordinates, its status
(done, failed, or not run -- the runner was stopped before it), and the
numbers the tables use, taken from ``metrics.json``, ``result.json`` and
``attempt.json`` by the dotted paths in :data:`METRIC_COLUMNS` (each
metric's own columns, from the metric registry) and :data:`COST_COLUMNS`.

The files are read through their models (:mod:`albot1.records`), and every
column's path is checked against its model when the column is defined: a
column naming a field that does not exist fails at import (and in the unit
tests), instead of silently becoming an empty column. A cell is empty only
when its run has no number there (a metric that does not apply, ``null``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from albot1.bench.grid import Cell, GridPlan
from albot1.bench.store import ATTEMPT, METRICS, Failure, ResultsStore
from albot1.contract import MapData
from albot1.data.degrade import parse_spec
from albot1.geometry.types import FloatArray
from albot1.metrics.record import MetricsRecord
from albot1.metrics.registry import MetricRegistry, metric_registry
from albot1.metrics.unit import ColumnSpec, Metric
from albot1.records import (
    AttemptRecord,
    Record,
    ResultRecord,
    check_number_path,
    number_at,
    read_record,
)
from albot1.runs.folder import StoredRun, read_run
from albot1.runs.folder import is_complete as run_is_complete

Source = Literal["metrics", "result", "attempt"]
#: the record model behind each column source (``metrics.json``, ``result.json``, ``attempt.json``)
SOURCE_MODELS: dict[Source, type[Record]] = {
    "metrics": MetricsRecord,
    "result": ResultRecord,
    "attempt": AttemptRecord,
}


@dataclass(frozen=True)
class Column:
    """One table column: the number at ``path`` in the ``source`` record, shown under ``header``.

    The path is checked against the source's model on creation (KeyError
    when it names no numeric field), so a typo cannot become an empty column.
    ``applies`` (metrics columns only) may declare the number not applicable
    to a run although it was computed (a loop gap on a route that never
    returns): it returns the reason, or None when the number applies.
    """

    source: Source
    path: str
    header: str
    applies: Callable[[MetricsRecord], str | None] | None = None
    #: where the column comes from: a metric's name (its ``columns``; docs/metrics.md), or "" for the cost table
    metric: str = ""
    #: why the number is null in a computed block (e.g. a precision without a claim), when the metric says
    undefined: str | None = None

    def __post_init__(self) -> None:
        check_number_path(SOURCE_MODELS[self.source], self.path)

    def _record(self, record: CellRecord) -> Record | None:
        sources: dict[Source, Record | None] = {
            "metrics": record.metrics,
            "result": record.result,
            "attempt": record.attempt,
        }
        return sources[self.source]

    def value(self, record: CellRecord) -> float | None:
        """The cell's number (None: the run has none there, e.g. a metric that does not apply)."""
        if self.source != "metrics" and _external(record):
            return None
        if self.applies is not None and record.metrics is not None and self.applies(record.metrics) is not None:
            return None
        return number_at(self._record(record), self.path)

    def reason(self, record: CellRecord) -> str | None:
        """Why a completed cell has no number here (None when it has one): the record's own words."""
        if record.status != "done" or self.value(record) is not None:
            return None
        if self.source != "metrics" and _external(record):
            return NOT_TIMED
        if self.applies is not None and record.metrics is not None:
            verdict = self.applies(record.metrics)
            if verdict is not None:
                return verdict
        if self.source == "result" and self.metric and record.metrics is not None:
            # a method's counter beside the metric that judges it: absent for the metric's own reason
            # (a method without a network of places has neither its counters nor the places metric)
            missing = record.metrics.reason(self.metric)
            if missing is not None:
                return missing
        if self.source == "result" and record.result is not None and self.path.startswith("timing.per_scan_"):
            why = record.result.timing.per_scan_reason  # a batch method: its per-scan times are not its cost
            if why is not None:
                return why
        if self.source != "metrics" or record.metrics is None:
            return f"no {self.source}.json value"
        return _null_reason(record.metrics, self.path, self.undefined)


#: Why an external run (another system's trajectory file, albot1.runs.external_run) has no cost numbers.
NOT_TIMED = "an external trajectory comes without timings or counters (not measured)"


def _external(record: CellRecord) -> bool:
    """Whether the cell scored another system's file: its result.json timing is zeros by necessity, not data."""
    return record.cell.trajectory is not None


def _null_reason(metrics: MetricsRecord, path: str, undefined: str | None = None) -> str:
    """The ``<name>_reason`` nearest the null along ``path`` (the convention of metrics.json), else a plain note."""
    parts = path.split(".")
    node: object = metrics
    reason = undefined or "not defined for this run (see its metrics.json)"
    for part in parts:
        if node is None:
            break
        named = getattr(node, f"{part}_reason", None)
        if isinstance(named, str):
            return named
        if getattr(node, "pairs", None) == 0:
            return "no pairs to measure on this route (pairs: 0)"
        unsought = getattr(node, "pairs_reason", None)  # no pairs were sought (a loop gap without reference poses)
        if isinstance(unsought, str):
            return unsought
        node = getattr(node, part, None)
    return reason


def metric_columns(registry: MetricRegistry) -> dict[str, Column]:
    """The accuracy columns: each metric's own :attr:`~albot1.metrics.unit.Metric.columns`, in registry order."""
    columns: dict[str, Column] = {}
    for metric in registry:
        for spec in metric.columns:
            if spec.key in columns:
                raise KeyError(f"report column {spec.key!r} of metric {metric.name!r} is already {columns[spec.key]}")
            if spec.source == "result":
                columns[spec.key] = Column("result", spec.path, spec.header, metric=metric.name)
                continue
            columns[spec.key] = Column(
                "metrics",
                f"{metric.name}.{spec.path}",
                spec.header,
                applies=_applies(metric, spec) if spec.applies is not None else None,
                metric=metric.name,
                undefined=spec.undefined,
            )
    return columns


def _applies(metric: Metric[Any], spec: ColumnSpec[Any]) -> Callable[[MetricsRecord], str | None]:
    """A column's rule on the metric's block (and the run's other blocks) as a rule on the record."""
    rule = spec.applies
    assert rule is not None

    def applies(metrics: MetricsRecord) -> str | None:
        block = metrics.get(metric)
        return None if block is None else rule(block, metrics)

    return applies


#: accuracy numbers, identical for identical inputs (from the metric registry)
METRIC_COLUMNS: dict[str, Column] = metric_columns(metric_registry())
#: cost numbers: they vary from run to run and machine to machine, so they live in their own table
COST_COLUMNS: dict[str, Column] = {
    "per_scan_ms_median": Column("result", "timing.per_scan_ms_median", "per-scan median (ms)"),
    "per_scan_ms_mean": Column("result", "timing.per_scan_ms_mean", "per-scan mean (ms)"),
    "per_scan_ms_p95": Column("result", "timing.per_scan_ms_p95", "per-scan p95 (ms)"),
    "total_s": Column("result", "timing.total_s", "total (s)"),
    "startup_s": Column("result", "timing.startup_s", "start-up (s)"),
    "peak_mb": Column("result", "timing.peak_mb", "peak (MB)"),
    "cell_s": Column("attempt", "elapsed_s", "cell wall (s)"),
}
KEY_COLUMNS = ("dataset", "method", "degradation")


@dataclass
class CellRecord:
    """One planned cell and what the store holds for it."""

    cell: Cell
    status: str  # done | failed | not run
    run_dir: Path
    result: ResultRecord | None
    metrics: MetricsRecord | None
    failure: Failure | None
    attempt: AttemptRecord | None = None
    _stored: StoredRun | None = field(default=None, repr=False, compare=False)
    _map: MapData | None = field(default=None, repr=False, compare=False)
    _geometry: FloatArray | None = field(default=None, repr=False, compare=False)

    def stored_run(self) -> StoredRun:
        """The run folder read back, once per record (several plots draw the same run)."""
        if self._stored is None:
            self._stored = read_run(self.run_dir)
        return self._stored

    def stored_map(self) -> MapData:
        """The run's map read back, once per record.

        The maps figure and the interactive view each read it twice (its extent, then its drawing); a whole-log
        line map is megabytes of GeoJSON, and decoding it was a tenth of the default report's figure time.
        """
        if self._map is None:
            self._map = self.stored_run().load_map()
        return self._map

    def map_geometry(self) -> FloatArray:
        """:meth:`MapData.geometry_points` of :meth:`stored_map` (the points that frame a map), once per record."""
        if self._geometry is None:
            geometry = np.asarray(self.stored_map().geometry_points(), dtype=float).reshape(-1, 2)
            geometry.setflags(write=False)  # shared by every figure of the record
            self._geometry = geometry
        return self._geometry


def collect(results_dir: str | Path) -> tuple[GridPlan, list[CellRecord]]:
    """The plan of ``results_dir`` and a record per planned cell (suite order).

    A completed cell whose ``result.json`` or ``metrics.json`` does not fit
    its model is a RecordError naming the file and the field (e.g. a results
    folder made by an older version: run ``albot1 bench`` again). A run marked
    DONE whose ``metrics.json`` is there but unreadable (truncated, edited) is
    such a cell too, not "not run": that would blame a stopped runner for a
    damaged file. Only a DONE run with no ``metrics.json`` at all was stopped
    between its run and its evaluation.

    A cell planned twice under the same labels (two spellings of one slice in a suite, ``NAME[:5]`` and
    ``NAME[0:5]``: one key, one run folder) is one record: each copy was a row of its table group, so the
    std, the median and the ``planned`` count were taken over the run counted twice (seeds 0 and 1 twice each:
    std 0.018 where the two seeds give 0.023).
    """
    store = ResultsStore(results_dir)
    plan = store.read_plan()
    records: list[CellRecord] = []
    seen: set[tuple[str, str, str]] = set()
    for cell in plan.cells:
        identity = (cell.key, cell.dataset_label, cell.method_label)
        if identity in seen:
            continue
        seen.add(identity)
        run_dir = store.run_dir(cell.key)
        if store.is_complete(cell.key) or (run_is_complete(run_dir) and (run_dir / METRICS).exists()):
            attempt = run_dir / ATTEMPT  # absent when the runner stopped right after the evaluation
            records.append(
                CellRecord(
                    cell,
                    "done",
                    run_dir,
                    store.read_result(cell.key),
                    read_record(MetricsRecord, run_dir / METRICS),
                    None,
                    read_record(AttemptRecord, attempt) if attempt.is_file() else None,
                )
            )
            continue
        failure = store.failure(cell.key)
        records.append(CellRecord(cell, "failed" if failure else "not run", run_dir, None, None, failure))
    return plan, records


def as_of(records: list[CellRecord]) -> str:
    """When the newest of ``records``' cells finished (``attempt.json``), as a report's date line says it.

    A report states the date of its data, not the clock's: a report built
    again from the same store is then the same bytes (a re-run of `make bench`
    with nothing new changes nothing, and skips the build: albot1.report.build_stamp).
    """
    finished = [r.attempt.finished for r in records if r.attempt is not None and r.attempt.finished]
    if not finished:
        return "no cell has finished"
    newest = max(finished)  # ISO 8601 UTC (2026-11-27T02:34:33Z): the text order is the time order
    return f"newest cell finished {newest[:10]} {newest[11:16]} UTC"


def cell_columns() -> list[str]:
    """The keys of a :func:`cell_rows` row, in order (the columns of an empty table too)."""
    columns = ["dataset", "method", "degradation", "seed", "status", "key", "scans"]
    for name in {**METRIC_COLUMNS, **COST_COLUMNS}:
        columns += [name, f"{name}_na"]
    return [*columns, "failure_kind", "reason"]


def cell_rows(records: list[CellRecord]) -> list[dict[str, Any]]:
    """Flat rows (one per cell): coordinates, status, every metric and cost column and, as ``<column>_na``,
    why a completed cell has no number there (:meth:`Column.reason`)."""
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
            "scans": rec.result.scans if rec.result is not None else None,
        }
        for name, column in {**METRIC_COLUMNS, **COST_COLUMNS}.items():
            row[name] = column.value(rec)
            row[f"{name}_na"] = column.reason(rec)
        row["failure_kind"] = rec.failure.kind if rec.failure else None
        row["reason"] = rec.failure.reason if rec.failure else None
        rows.append(row)
    return rows


def severity_order(levels: list[str]) -> list[str]:
    """none, Gaussian levels by sigma, biases, the thesis's degradation, then the set-up ones (offset, dropout).

    Within a kind by size, whatever the sign (``bias:0.01:0.1`` before ``bias:-0.05:-1``; a signed order put
    every negative bias first, however large), then by sign, so the order is one.
    """
    rank = {"none": 0, "gauss": 1, "bias": 2, "thesis": 3, "offset": 4, "dropout": 5}

    def key(level: str) -> tuple[int, float, float, float, float, float]:
        spec = parse_spec(level, stored=True)
        return rank.get(spec.kind, 6), abs(spec.a), abs(spec.b), abs(spec.c), spec.a, spec.b

    return sorted(levels, key=key)
