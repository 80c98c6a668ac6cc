"""``relation_box``: the distribution of the per-relation errors, as a box plot draws it.

Why: the relation metric (``relations``) reports means and standard
deviations, which one bad stretch of a log dominates; a box plot of the
per-relation errors (the form published comparisons use) needs the quartiles,
the Tukey whiskers and the number of outliers. The errors are those of the
relation metric, the same relations the same way
(:func:`albot1.metrics.relations.relation_errors`, relations outside the run
left out). Quartiles are numpy's default (linear, Hyndman-Fan type 7), as
matplotlib's ``boxplot`` computes them; the whiskers reach the most extreme
error within 1.5 IQR of the box.

This module is the whole metric: the registry finds it, ``metrics.json`` gets
its block, ``albot1 evaluate`` its headline and the report its columns.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.metrics.blocks import block_of, fmt
from albot1.metrics.relations import relation_errors
from albot1.metrics.unit import RELATIONS, ColumnSpec, Metric, MetricInputs
from albot1.records import Count, OptFloat, Record

#: The whiskers' reach beyond the box, in IQRs (Tukey's; matplotlib's default ``whis``).
WHISKER_IQR = 1.5


class Quartiles(Record):
    """Box-plot numbers of one error sample (null statistics when ``n`` is 0)."""

    n: Count
    min: OptFloat
    q1: OptFloat
    median: OptFloat
    q3: OptFloat
    max: OptFloat
    iqr: OptFloat
    whisker_low: OptFloat
    whisker_high: OptFloat
    outliers: Count


class RelationBoxBlock(Record):
    """``relation_box``: quartiles, whiskers and outliers of the per-relation errors (m, deg)."""

    units: dict[str, str]
    quantiles: str
    whisker_iqr: float
    relations_used: Count
    translation_m: Quartiles
    rotation_deg: Quartiles


def quartiles(values: NDArray[np.float64], whisker_iqr: float = WHISKER_IQR) -> dict[str, Any]:
    """The :class:`Quartiles` of ``values`` as plain data (NaN statistics for an empty sample)."""
    v = np.sort(np.asarray(values, dtype=float).ravel())
    if v.size == 0:
        nan = float("nan")
        stats = ("min", "q1", "median", "q3", "max", "iqr", "whisker_low", "whisker_high")
        return {"n": 0, **dict.fromkeys(stats, nan), "outliers": 0}
    q1, median, q3 = (float(q) for q in np.quantile(v, [0.25, 0.5, 0.75]))
    iqr = q3 - q1
    inside = v[(v >= q1 - whisker_iqr * iqr) & (v <= q3 + whisker_iqr * iqr)]
    low, high = float(inside.min()), float(inside.max())
    return {
        "n": int(v.size),
        "min": float(v[0]),
        "q1": q1,
        "median": median,
        "q3": q3,
        "max": float(v[-1]),
        "iqr": iqr,
        "whisker_low": low,
        "whisker_high": high,
        "outliers": int(np.count_nonzero((v < low) | (v > high))),
    }


def compute(inputs: MetricInputs) -> RelationBoxBlock:
    assert inputs.relations is not None  # RELATIONS is a need
    errors, used = relation_errors(
        inputs.relation_timestamps,
        inputs.relation_poses,
        inputs.relations,
        outside="exclude",
        source=inputs.relations_source,
    )
    return block_of(
        RelationBoxBlock,
        {
            "units": {"translation": "m", "rotation": "deg"},
            "quantiles": "numpy linear (type 7), as matplotlib's boxplot",
            "whisker_iqr": WHISKER_IQR,
            "relations_used": int(used.sum()),
            "translation_m": quartiles(np.hypot(errors[:, 0], errors[:, 1])),
            "rotation_deg": quartiles(np.degrees(np.abs(errors[:, 2]))),
        },
    )


def headline(block: RelationBoxBlock) -> str:
    t, r = block.translation_m, block.rotation_deg
    return (
        f"median {fmt(t.median)} m (IQR {fmt(t.q1)}-{fmt(t.q3)}), {fmt(r.median, '.2f')} deg "
        f"(IQR {fmt(r.q1, '.2f')}-{fmt(r.q3, '.2f')}), {t.outliers} + {r.outliers} outliers of N = {t.n}"
    )


METRIC = Metric(
    name="relation_box",
    position=120,
    models=(RelationBoxBlock,),
    needs=(RELATIONS,),
    compute=compute,
    headline=headline,
    columns=(
        ColumnSpec("relation_median_m", "translation_m.median", "relation trans. median (m)"),
        ColumnSpec("relation_iqr_m", "translation_m.iqr", "relation trans. IQR (m)"),
    ),
)
