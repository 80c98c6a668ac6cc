"""The pieces several metric blocks share: summary statistics and the alignment a metric applied.

Why here: the blocks of ``metrics.json`` are typed where their metric is
defined (one module per metric in :mod:`albot1.metrics.measures`), and the
summary every error metric reports (:func:`albot1.metrics.stats.summarize`)
must be one model, not one per metric. :func:`block_of` turns what a metric's
maths returns (plain data with numpy scalars and NaN) into its block, by the
same conversion ``metrics.json`` is read with (:func:`albot1.records.json_value`),
so a block in memory holds exactly what its file will hold.
"""

from __future__ import annotations

from typing import ClassVar, Literal, TypeVar

from albot1.records import Count, OmitsAbsentReasons, OptNonNegative, Record, parse_record

BlockT = TypeVar("BlockT", bound=Record)

Alignment = Literal["none", "first", "rigid"]


def block_of(model: type[BlockT], data: object) -> BlockT:
    """``data`` (numpy values and NaN allowed) validated as ``model``; RecordError names the model and the field.

    A RecordError here is a bug of the metric (its maths and its block
    disagree), so :func:`albot1.runs.evaluate.score` lets it through instead
    of recording it as a reason.
    """
    return parse_record(model, data, f"the {model.__name__} being computed")


class Stats(Record):
    """The shared summary of a sample (:func:`albot1.metrics.stats.summarize`); null statistics when ``n`` is 0."""

    mean: OptNonNegative
    std: OptNonNegative
    median: OptNonNegative
    min: OptNonNegative
    max: OptNonNegative
    rmse: OptNonNegative
    n: Count
    std_ddof: Count


class RotationStats(Record):
    """:class:`Stats` of a heading error with the unit in the key (``_deg``)."""

    mean_deg: OptNonNegative
    std_deg: OptNonNegative
    median_deg: OptNonNegative
    min_deg: OptNonNegative
    max_deg: OptNonNegative
    rmse_deg: OptNonNegative
    n: Count
    std_ddof: Count


class AlignmentTransform(OmitsAbsentReasons):
    """The rigid motion an alignment applied to the estimate (m, deg).

    ``n_to_align``: the motion was estimated on the first N pose pairs only
    (``albot1 evaluate --align first:N``); absent when all pairs were used.
    """

    OMITTED_WHEN_NULL: ClassVar[frozenset[str]] = frozenset({"n_to_align"})

    method: Alignment
    x_m: float
    y_m: float
    theta_deg: float
    n_to_align: int | None = None


def fmt(value: float | None, spec: str = ".3f") -> str:
    """``value`` formatted for a headline, ``n/a`` when undefined (null in the file)."""
    return "n/a" if value is None else format(value, spec)
