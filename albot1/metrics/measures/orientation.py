"""``orientation``: the thesis's Table 3.1, bearing and distance to the start (:mod:`albot1.metrics.orientation`)."""

from __future__ import annotations

from albot1.metrics.blocks import block_of, fmt
from albot1.metrics.orientation import orientation_table
from albot1.metrics.unit import REFERENCE, ColumnSpec, Metric, MetricInputs
from albot1.records import Count, OptFloat, OptNonNegative, Record


class OrientationRow(Record):
    """One stop point of the thesis's Table 3.1 (deg, m); the bearing error is null near the start."""

    scan: Count
    timestamp: OptFloat
    travel_m: float
    estimate_bearing_deg: OptFloat  # null where the estimate is on its own start (no direction home)
    estimate_distance_m: float
    reference_bearing_deg: float
    reference_distance_m: float
    bearing_error_deg: OptFloat
    distance_error_m: float


class OrientationBlock(Record):
    """``orientation``: Table 3.1 rows and mean/max absolute differences (null when no row defines them)."""

    alignment: str
    units: dict[str, str]
    every_m: float
    min_distance_m: float
    stops: Count
    bearing_undefined: Count
    bearing_abs_error_mean_deg: OptNonNegative
    bearing_abs_error_max_deg: OptNonNegative
    distance_abs_error_mean_m: OptNonNegative
    distance_abs_error_max_m: OptNonNegative
    rows: list[OrientationRow]


def compute(inputs: MetricInputs) -> OrientationBlock:
    assert inputs.reference is not None  # REFERENCE is a need
    return block_of(OrientationBlock, orientation_table(inputs.poses, inputs.reference, inputs.timestamps))


#: why the bearing error is null in a computed block (the report's not-applicable note and the headline say it)
BEARING_UNDEFINED = "no stop point where the start's bearing is defined (none 1 m or more from the start)"
#: why the bearing error is null when the estimate stood on its start wherever the start's bearing is defined
ESTIMATE_AT_START = (
    "the estimate is on its own start at every stop point 1 m or more from the start (it did not move): "
    "it has no bearing home"
)
#: why every mean is null: the first scan is no stop point (the start itself), so a one-scan run has none
NO_STOPS = "no stop point: the run has no scan after its first"


def estimate_at_start(block: OrientationBlock, _: object = None) -> str | None:
    """:data:`ESTIMATE_AT_START` when that is why the bearing mean is null, else None (the report's column rule)."""
    if block.bearing_abs_error_mean_deg is not None:
        return None
    far = [row for row in block.rows if row.reference_distance_m >= block.min_distance_m]
    return ESTIMATE_AT_START if far and all(row.estimate_bearing_deg is None for row in far) else None


def headline(block: OrientationBlock) -> str:
    """The means, or n/a with the reason (a bare "n/a deg" gave none)."""
    if block.stops == 0:
        return NO_STOPS
    bearing = block.bearing_abs_error_mean_deg
    why = estimate_at_start(block) or BEARING_UNDEFINED
    bearing_text = f"{fmt(bearing, '.2f')} deg" if bearing is not None else f"n/a ({why})"
    return (
        f"{block.stops} stops, bearing |err| mean {bearing_text}, "
        f"distance |err| mean {fmt(block.distance_abs_error_mean_m)} m"
    )


METRIC = Metric(
    name="orientation",
    position=60,
    models=(OrientationBlock,),
    needs=(REFERENCE,),
    compute=compute,
    headline=headline,
    columns=(
        ColumnSpec(
            "orientation_deg",
            "bearing_abs_error_mean_deg",
            "bearing error mean (deg)",
            applies=estimate_at_start,
            undefined=BEARING_UNDEFINED,
        ),
    ),
)
