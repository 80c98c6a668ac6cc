"""``ate``: absolute trajectory error after an alignment (:func:`albot1.metrics.ate.ate`; rigid unless chosen)."""

from __future__ import annotations

from albot1.metrics.ate import ate
from albot1.metrics.blocks import Alignment, AlignmentTransform, RotationStats, block_of, fmt
from albot1.metrics.unit import REFERENCE, ColumnSpec, Metric, MetricInputs
from albot1.records import Count, NonNegative, Record


class AlignmentSummary(Record):
    """ATE under another alignment, for comparison."""

    rmse_m: NonNegative
    mean_m: NonNegative
    max_m: NonNegative


class AteBlock(Record):
    """``ate``: position error after ``alignment`` (m, population std), heading error under ``rotation``."""

    alignment: Alignment
    units: dict[str, str]
    mean_m: NonNegative
    std_m: NonNegative
    median_m: NonNegative
    min_m: NonNegative
    max_m: NonNegative
    rmse_m: NonNegative
    n: Count
    std_ddof: Count
    rotation: RotationStats
    alignment_transform: AlignmentTransform
    other_alignments: dict[str, AlignmentSummary]


def compute(inputs: MetricInputs) -> AteBlock:
    assert inputs.reference is not None  # REFERENCE is a need
    return block_of(AteBlock, ate(inputs.poses, inputs.reference, inputs.alignment, inputs.n_to_align))


def headline(block: AteBlock) -> str:
    n = block.alignment_transform.n_to_align
    on = f" on the first {n} pairs" if n is not None else ""
    return f"rmse {fmt(block.rmse_m)} m, max {fmt(block.max_m)} m ({block.alignment} alignment{on})"


METRIC = Metric(
    name="ate",
    position=10,
    models=(AteBlock,),
    needs=(REFERENCE,),
    compute=compute,
    headline=headline,
    columns=(ColumnSpec("ate_rmse_m", "rmse_m", "ATE RMSE (m)"),),
)
