"""``rpe``: relative pose error per step of frames or metres (:func:`albot1.metrics.rpe.rpe_set`)."""

from __future__ import annotations

from typing import Literal

from albot1.metrics.blocks import Stats, block_of, fmt
from albot1.metrics.rpe import rpe_set
from albot1.metrics.unit import REFERENCE, ColumnSpec, Metric, MetricInputs
from albot1.records import Count, OmitsAbsentReasons


class RpeEntry(OmitsAbsentReasons):
    """One RPE step: ``delta`` frames (an integer) or metres of reference travel.

    ``pairs_reason``: why there is no pair (``pairs`` 0, null statistics); absent otherwise.
    """

    delta: int | float
    delta_unit: Literal["frames", "m"]
    pairs: Count
    translation_m: Stats
    rotation_deg: Stats
    pairs_reason: str | None = None


class RpeBlock(OmitsAbsentReasons):
    """``rpe``: the first step's numbers at the top level, every step under ``deltas``."""

    alignment: str
    pairs_from: str
    units: dict[str, str]
    delta: int | float
    delta_unit: Literal["frames", "m"]
    pairs: Count
    translation_m: Stats
    rotation_deg: Stats
    deltas: list[RpeEntry]
    pairs_reason: str | None = None


def compute(inputs: MetricInputs) -> RpeBlock:
    assert inputs.reference is not None  # REFERENCE is a need
    return block_of(RpeBlock, rpe_set(inputs.poses, inputs.reference))


def headline(block: RpeBlock) -> str:
    if block.pairs_reason is not None:
        return f"delta {block.delta} {block.delta_unit}: n/a ({block.pairs_reason})"
    return (
        f"delta {block.delta} {block.delta_unit}: {fmt(block.translation_m.rmse)} m, "
        f"{fmt(block.rotation_deg.rmse)} deg rmse"
    )


METRIC = Metric(
    name="rpe",
    position=30,
    models=(RpeBlock,),
    needs=(REFERENCE,),
    compute=compute,
    headline=headline,
    columns=(
        ColumnSpec("rpe_frame_m", "translation_m.rmse", "RPE 1 scan trans. RMSE (m)"),
        ColumnSpec("rpe_frame_deg", "rotation_deg.rmse", "RPE 1 scan rot. RMSE (deg)"),
    ),
)
