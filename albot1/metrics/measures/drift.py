"""``drift``: relative error per travelled distance over every start point (:func:`albot1.metrics.drift.drift`)."""

from __future__ import annotations

from pydantic import model_validator

from albot1.metrics.blocks import Stats, block_of, fmt
from albot1.metrics.drift import drift
from albot1.metrics.unit import REFERENCE, ColumnSpec, Metric, MetricInputs
from albot1.records import Count, NonNegative, OmitsAbsentReasons, Record


class DriftEntry(Record):
    """``drift.sweep`` entry: errors of every segment of ``length_m`` reference travel."""

    length_m: NonNegative
    pairs: Count
    translation_m: Stats
    rotation_deg: Stats


class DriftAt10m(Record):
    """``drift.at_10m``: mean errors of the 10 m segments (the headline)."""

    translation_m: NonNegative
    rotation_deg: NonNegative
    pairs: Count


class DriftBlock(OmitsAbsentReasons):
    """``drift``: relative error per travelled distance over every start point.

    ``at_10m`` is null with ``at_10m_reason`` when the route has no 10 m segment.
    """

    alignment: str
    pairs_from: str
    start_spacing_m: NonNegative
    route_m: NonNegative
    units: dict[str, str]
    sweep: list[DriftEntry]
    lengths_beyond_route_m: list[float]
    at_10m: DriftAt10m | None
    at_10m_reason: str | None = None

    @model_validator(mode="after")
    def _value_or_reason(self) -> DriftBlock:
        if (self.at_10m is None) == (self.at_10m_reason is None):
            raise ValueError("at_10m: expected either the 10 m means or at_10m_reason, exactly one")
        return self


def compute(inputs: MetricInputs) -> DriftBlock:
    assert inputs.reference is not None  # REFERENCE is a need
    return block_of(DriftBlock, drift(inputs.poses, inputs.reference))


def headline(block: DriftBlock) -> str:
    at = block.at_10m
    if at is None:
        return f"no 10 m segment: {block.at_10m_reason}"
    return f"at 10 m: {fmt(at.translation_m)} m, {fmt(at.rotation_deg, '.2f')} deg mean over {at.pairs} segments"


METRIC = Metric(
    name="drift",
    position=40,
    models=(DriftBlock,),
    needs=(REFERENCE,),
    compute=compute,
    headline=headline,
    columns=(
        ColumnSpec("drift_10m_m", "at_10m.translation_m", "RPE@10 m trans. (m)"),
        ColumnSpec("drift_10m_deg", "at_10m.rotation_deg", "RPE@10 m rot. (deg)"),
    ),
)
