"""``cost``: per-scan time, totals, peak memory and growth with position (:func:`albot1.metrics.cost.cost`).

No report columns: cost numbers vary from machine to machine and have their
own table, read from ``result.json`` (:data:`albot1.report.collect.COST_COLUMNS`).
"""

from __future__ import annotations

from albot1.metrics.blocks import block_of, fmt
from albot1.metrics.cost import cost
from albot1.metrics.errors import MetricsError
from albot1.metrics.unit import TIMING, Metric, MetricInputs
from albot1.records import Count, NonNegative, OptFloat, OptNonNegative, Record, dump_record


class CostByPosition(Record):
    """``cost.by_position``: the median per-scan time in each tenth of the sequence."""

    scan_centres: list[float]
    per_scan_ms_median: list[float]


class CostBlock(Record):
    """``cost``: per-scan time (ms), totals (s), peak memory (MiB) and growth with position."""

    units: dict[str, str]
    scans: Count
    per_scan_ms_median: NonNegative
    per_scan_ms_p95: NonNegative
    per_scan_ms_mean: NonNegative
    per_scan_ms_max: NonNegative
    process_total_s: NonNegative
    total_s: OptNonNegative
    finish_s: OptNonNegative
    #: seconds before the first scan (compiling or loading kernels); None for runs recorded before it was measured
    startup_s: OptNonNegative = None
    peak_mb: OptNonNegative
    by_position: CostByPosition
    growth_slope_ms_per_1000_scans: OptFloat
    last_over_first_decile: OptFloat


def compute(inputs: MetricInputs) -> CostBlock:
    assert inputs.per_scan_ns is not None  # TIMING is a need
    if inputs.timing is not None and inputs.timing.per_scan_reason is not None:
        # a batch method: per-scan statistics and their growth would describe its bookkeeping, not its cost
        raise MetricsError(f"cost: {inputs.timing.per_scan_reason}")
    timing = dump_record(inputs.timing) if inputs.timing is not None else {}
    return block_of(CostBlock, cost(inputs.per_scan_ns, timing))


def headline(block: CostBlock) -> str:
    startup = f", start-up {fmt(block.startup_s, '.2f')} s" if block.startup_s else ""
    return (
        f"{fmt(block.per_scan_ms_median)} ms/scan median, p95 {fmt(block.per_scan_ms_p95)} ms, "
        f"peak {fmt(block.peak_mb, '.1f')} MiB{startup}"
    )


METRIC = Metric(
    name="cost",
    position=100,
    models=(CostBlock,),
    needs=(TIMING,),
    compute=compute,
    headline=headline,
)
