"""``updates``: views, updates, their ratio and every other counter of the method (:mod:`albot1.metrics.updates`)."""

from __future__ import annotations

from albot1.metrics.blocks import block_of
from albot1.metrics.unit import COUNTERS, ColumnSpec, Metric, MetricInputs
from albot1.metrics.updates import update_counts
from albot1.records import OptFloat, Record


class UpdatesBlock(Record):
    """``updates``: views, updates, their ratio (null for no views) and every other counter of the method."""

    units: str
    views: int | float
    updates: int | float
    updates_per_view: OptFloat
    counters: dict[str, int | float]


def compute(inputs: MetricInputs) -> UpdatesBlock:
    return block_of(UpdatesBlock, update_counts(dict(inputs.counters or {})))


def headline(block: UpdatesBlock) -> str:
    return f"{block.updates} updates / {block.views} views"


METRIC = Metric(
    name="updates",
    position=90,
    models=(UpdatesBlock,),
    needs=(COUNTERS,),
    compute=compute,
    headline=headline,
    columns=(
        ColumnSpec("updates_per_view", "updates_per_view", "updates/view", undefined="the run saw no views (views: 0)"),
    ),
)
