"""``places``: a network of places (thesis chapter 4) judged against the reference poses.

The method's own claims (``places.json``: visits, claimed re-visits, exit
crossings and predictions; :mod:`albot1.methods.albot1.places.network`) are
scored after the run, when the run folder is evaluated: the mapper never sees
the reference poses. :func:`albot1.metrics.places.judge_network` holds the
rules; the dataset's metadata (the synthetic worlds' rooms, doorways and true
doorway crossings) is read from the reopened dataset. A method without a
network of places has no ``places.json``: the metric is not applicable, with
that reason.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Literal

from albot1.errors import Albot1Error
from albot1.metrics.blocks import block_of, fmt
from albot1.metrics.errors import MetricsError
from albot1.metrics.places import PLACES_JSON, judge_network
from albot1.metrics.unit import REFERENCE, ColumnSpec, Metric, MetricInputs, method_file
from albot1.records import Count, NonNegative, OmitsAbsentReasons, OptFraction, OptNonNegative, Record

PLACES_FILE = method_file(PLACES_JSON, f"the method keeps no network of places (no {PLACES_JSON})")


class VisitJudgement(Record):
    """One visit: the earlier visits it was in the same place as, and whether the network recognised that."""

    visit: Count
    same_place_as: list[int]
    recognised: bool


class ExitPrediction(Record):
    """One exit prediction compared at a crossing, against the true doorway nearest the perceived exit (m)."""

    scan: Count
    exit: int | str
    doorway: str
    perceived_error_m: NonNegative
    aligned_error_m: NonNegative
    not_aligned_error_m: NonNegative


class ExitsJudgement(OmitsAbsentReasons):
    """Exit predictions against the true doorways, and detected crossings against the true ones.

    The errors' means and medians are null when no prediction was compared,
    ``exit_predictions_reason`` then saying why in the run's own terms (no
    place recognised, none with another exit, the run ended first, or a new
    way out). The medians are absent from a file written before they
    existed (read as null).
    """

    exit_predictions: list[ExitPrediction]
    crossing_scans: Count
    exit_prediction_aligned_true_mean_m: OptNonNegative
    exit_prediction_not_aligned_true_mean_m: OptNonNegative
    exit_prediction_aligned_true_median_m: OptNonNegative = None
    exit_prediction_not_aligned_true_median_m: OptNonNegative = None
    crossings_true: Count
    crossings_false: Count
    crossings_missed: Count
    exit_predictions_reason: str | None = None


class PlacesBlock(OmitsAbsentReasons):
    """``places``: re-visits judged by the reference positions (``rule``), and exits when the dataset knows doorways.

    ``rule`` is ``rooms`` (the dataset's rooms; ``rooms`` names each visit's;
    a re-visit is a visit in a later stay in the room, consecutive visits in
    one room being one stay)
    or ``overlap`` (hulls of reference positions grown by ``buffer_m``
    sharing ``min_overlap``). ``claims_true`` flags each claimed re-visit of
    ``places.json`` in its order. Precision is null without a claim, recall
    without a true re-visit. ``exits`` is null with ``exits_reason`` when the
    dataset knows no doorways.
    """

    units: dict[str, str]
    rule: Literal["rooms", "overlap"]
    rooms: list[str] | None
    buffer_m: float | None
    min_overlap: float | None
    claims: Count
    claims_true: list[bool]
    revisits_true: Count
    revisits_false: Count
    revisits_missed: Count
    revisits_actual: Count
    revisit_precision: OptFraction
    revisit_recall: OptFraction
    visits: list[VisitJudgement]
    exits: ExitsJudgement | None
    exits_reason: str | None = None


def compute(inputs: MetricInputs) -> PlacesBlock:
    reference, read_file = inputs.reference, inputs.read_file
    assert reference is not None and read_file is not None  # REFERENCE and PLACES_FILE are needs
    record = read_file(PLACES_JSON)
    if not isinstance(record, Mapping):
        raise MetricsError(f"{PLACES_JSON}: expected a JSON object, found {type(record).__name__}")
    try:
        extra = inputs.open_dataset().metadata.extra
    except Albot1Error as exc:
        raise MetricsError(f"cannot reopen dataset {inputs.dataset!r} for its rooms and doorways: {exc}") from exc
    try:
        data = judge_network(record, inputs.timestamps, inputs.poses, reference, extra)
    except (KeyError, TypeError, IndexError) as exc:
        raise MetricsError(f"{PLACES_JSON}: unexpected content ({type(exc).__name__}: {exc})") from None
    return block_of(PlacesBlock, data)


def headline(block: PlacesBlock) -> str:
    text = (
        f"{block.revisits_true} of {block.claims} claimed re-visits true (precision "
        f"{fmt(block.revisit_precision, '.2f')}), recall {fmt(block.revisit_recall, '.2f')} "
        f"of {block.revisits_actual} true re-visits ({block.rule})"
    )
    exits = block.exits
    if exits is None:
        return f"{text}; {block.exits_reason or 'no exit checks'}"
    crossings = (
        f"{exits.crossings_true} of {exits.crossings_true + exits.crossings_missed} true crossings found, "
        f"{exits.crossings_false} false"
    )
    if not exits.exit_predictions:
        return f"{text}; {crossings}; {exits.exit_predictions_reason or 'no exit prediction compared'}"
    return (
        f"{text}; {crossings}; {len(exits.exit_predictions)} exit prediction"
        f"{'' if len(exits.exit_predictions) == 1 else 's'} compared, mean (median) "
        f"{fmt(exits.exit_prediction_aligned_true_mean_m)} ({fmt(exits.exit_prediction_aligned_true_median_m)}) m "
        f"aligned, {fmt(exits.exit_prediction_not_aligned_true_mean_m)} "
        f"({fmt(exits.exit_prediction_not_aligned_true_median_m)}) m not"
    )


def _exit_errors_apply(block: PlacesBlock, _: object) -> str | None:
    """The run's own reason when no exit prediction was compared (None: the errors apply, or exits are null)."""
    return None if block.exits is None else block.exits.exit_predictions_reason


METRIC = Metric(
    name="places",
    position=110,
    models=(PlacesBlock,),
    needs=(PLACES_FILE, REFERENCE),
    compute=compute,
    headline=headline,
    columns=(
        # the network's size and its claims are the method's own counters (result.json), shown beside the judgement
        ColumnSpec("places", "counters.places", "places", source="result"),
        ColumnSpec("revisits_claimed", "counters.revisits_confirmed", "re-visits claimed", source="result"),
        ColumnSpec(
            "revisit_precision", "revisit_precision", "re-visit precision", undefined="no re-visit claimed (claims: 0)"
        ),
        ColumnSpec(
            "revisit_recall", "revisit_recall", "re-visit recall", undefined="no true re-visit (revisits_actual: 0)"
        ),
        # null exits: the block's exits_reason; no prediction compared: the run's exit_predictions_reason
        # (a file written before that reason existed: the undefined note)
        *(
            ColumnSpec(
                key,
                f"exits.exit_prediction_{which}_true_mean_m",
                header,
                applies=_exit_errors_apply,
                undefined="no exit prediction compared (exits.exit_predictions: [])",
            )
            for key, which, header in (
                ("exit_aligned_m", "aligned", "exit pred. aligned (m)"),
                ("exit_not_aligned_m", "not_aligned", "exit pred. not aligned (m)"),
            )
        ),
    ),
)
