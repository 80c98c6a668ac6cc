"""``loop_gap``: the thesis's loop gap, route end vs start and every revisit pair (:mod:`albot1.metrics.loop_gap`).

Two block shapes: with reference poses every revisit pair is scored
(:class:`LoopGapBlock`); without them, on a route the dataset declares
closed, only the route gap is (:class:`ClosedRouteGapBlock`).
"""

from __future__ import annotations

from albot1.metrics.blocks import Stats, block_of, fmt
from albot1.metrics.loop_gap import MIN_TRAVEL_M, pair_gaps, route_gap
from albot1.metrics.measures.drift import METRIC as DRIFT
from albot1.metrics.unit import NO_REFERENCE, RETURNING_ROUTE, BlockLookup, ColumnSpec, Metric, MetricInputs
from albot1.records import Count, NonNegative, Record

#: A loop gap applies to a route whose reference returns near its start: within this many metres ...
ROUTE_RETURN_M = 1.0
#: ... or this fraction of the route's length, whichever is larger (docs/metrics.md, "Loop gap").
ROUTE_RETURN_FRACTION = 0.02


class RouteGap(Record):
    """``loop_gap.route``: start-to-end error (m, deg)."""

    estimated_offset_m: NonNegative
    reference_offset_m: NonNegative
    reference: str
    gap_m: NonNegative
    heading_gap_deg: NonNegative


class WorstPair(Record):
    """The revisit pair with the largest gap."""

    scans: list[int]
    gap_m: NonNegative


class LoopGapBlock(Record):
    """``loop_gap`` with reference poses: the route gap and every revisit pair.

    With ``pairs: 0`` the pair statistics and ``worst_pair`` are null. ``pairs_same_stamp``: the pairs whose two
    scans share a stamp, held to the travel bound alone (absent from files written before it was counted).
    """

    units: dict[str, str]
    alignment: str
    route: RouteGap
    radius_m: NonNegative
    min_dt_s: NonNegative
    min_travel_m: NonNegative
    pairs: Count
    translation_m: Stats | None
    rotation_deg: Stats | None
    worst_pair: WorstPair | None
    pairs_same_stamp: Count | None = None


class ClosedRouteGapBlock(Record):
    """``loop_gap`` without reference poses on a route declared closed: the route gap only.

    Revisit pairs need reference positions, so ``pairs`` is null and
    ``pairs_reason`` says why.
    """

    units: dict[str, str]
    alignment: str
    route: RouteGap
    pairs: None
    pairs_reason: str


Block = LoopGapBlock | ClosedRouteGapBlock

UNITS = {"gap": "m", "heading": "deg"}
ALIGNMENT = "none (relative poses)"


def compute(inputs: MetricInputs) -> Block:
    poses, reference = inputs.poses, inputs.reference
    if reference is None:  # RETURNING_ROUTE is a need: the route is declared closed
        return block_of(
            ClosedRouteGapBlock,
            {
                "units": UNITS,
                "alignment": ALIGNMENT,
                "route": route_gap(poses, None),
                "pairs": None,
                "pairs_reason": NO_REFERENCE,
            },
        )
    return block_of(
        LoopGapBlock,
        {
            "units": UNITS,
            "alignment": ALIGNMENT,
            "route": route_gap(poses, reference),
            **pair_gaps(inputs.timestamps, poses, reference),
        },
    )


def headline(block: Block) -> str:
    pairs = block.translation_m if isinstance(block, LoopGapBlock) else None
    extra = f", {block.pairs} revisit pairs mean {fmt(pairs.mean)} m max {fmt(pairs.max)} m" if pairs else ""
    return f"route gap {fmt(block.route.gap_m)} m{extra}"


def route_returns(block: Block, others: BlockLookup) -> str | None:
    """None when the route goes out and returns to its start (a loop gap means something), else why it does not apply.

    A route that never leaves its start (a robot parked or turning on the spot, the first metres of a log) ends
    within the return bound too, but closes no loop: it must travel at least :data:`MIN_TRAVEL_M` of reference
    path, the bound a revisit pair is held to. Its "loop gap" was the drift over a few centimetres.
    """
    offset = block.route.reference_offset_m
    drift = others.get(DRIFT)
    route = drift.route_m if drift is not None else 0.0
    if drift is not None and route < MIN_TRAVEL_M:
        return (
            f"the route never leaves its start to return to it (it travels {route:.1f} m; a loop needs at least "
            f"{MIN_TRAVEL_M:g} m)"
        )
    allowed = max(ROUTE_RETURN_M, ROUTE_RETURN_FRACTION * route)
    if offset <= allowed:
        return None
    return f"the route does not return to its start (it ends {offset:.1f} m away; a loop closes within {allowed:.1f} m)"


METRIC: Metric[Block] = Metric(
    name="loop_gap",
    position=50,
    models=(LoopGapBlock, ClosedRouteGapBlock),
    needs=(RETURNING_ROUTE,),
    compute=compute,
    headline=headline,
    columns=(
        ColumnSpec("loop_gap_m", "route.gap_m", "loop gap (m)", applies=route_returns),
        ColumnSpec("revisit_gap_m", "translation_m.mean", "revisit gap mean (m)"),
    ),
)
