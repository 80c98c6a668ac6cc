"""Experiment 6 (3.2.6): public logs of the SLAM community, scored with the relation metric, Albot1 beside the
RBPF and graph baselines.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from functools import partial

from albot1.data import catalog
from albot1.metrics.paired import CONFIDENCE
from albot1.report.comparisons import Kind, compare_runs, position_errors_of, relation_errors_of
from albot1.report.thesis.evidence import Evidence
from albot1.report.thesis.experiments.common import (
    ATE,
    EXP6_BASELINES,
    ODOMETRY,
    RELATION_DEG,
    RELATION_M,
    RELATIONS_USED,
    VARIANTS,
    ClaimRow,
    FigureRequest,
    Section,
    cell,
    is_public,
    number,
    per_variant,
    store_of,
    table,
    tagged,
)
from albot1.report.thesis.experiments.published import published_relations
from albot1.report.thesis.verdicts import (
    Number,
    Verdict,
    lower_than,
    with_paired_test,
)


@dataclass(frozen=True)
class Scoring:
    """What Experiment 6 scores a run by: metrics.json paths of the error (m, deg) and of the count of pairs it
    is taken over, read from the runs at ``degradation``. The page uses :data:`RELATIONS`."""

    metres: str
    degrees: str
    count: str
    degradation: str = "none"


#: The relation metric of Kuemmerle et al. (2009) on the logs' own odometry: what the page scores.
RELATIONS = Scoring(RELATION_M, RELATION_DEG, RELATIONS_USED)


def paired_kind(scoring: Scoring) -> Kind | None:
    """The per-unit errors behind the scoring's figure, for its paired test (None: no such errors are kept)."""
    if scoring.metres == RELATION_M:
        return "relation translation"
    if scoring.metres == ATE:
        return "position"
    return None


def _reasonable_shape(ev: Evidence, scoring: Scoring, dataset: str, method: str) -> Verdict:
    """Lower than the odometry's error, by the paired test of the two runs (:func:`with_paired_test`)."""
    deg = scoring.degradation
    point = lower_than(
        number(ev, dataset, method, scoring.metres, f"{method} relation error", "m", deg),
        number(ev, dataset, ODOMETRY, scoring.metres, "odometry", "m", deg),
    )
    kind = paired_kind(scoring)
    mine, odometry = ev.find(dataset, method, deg).record, ev.find(dataset, ODOMETRY, deg).record
    if kind is None or mine is None or odometry is None:
        return point
    read = relation_errors_of if kind != "position" else position_errors_of
    return with_paired_test(point, compare_runs([(read(mine), read(odometry))], kind))


def section_public(ev: Evidence, scoring: Scoring = RELATIONS, candidates: Iterable[str] | None = None) -> Section:
    """Experiment 6 (3.2.6): a dataset of the SLAM community; the relation metric beside RBPF and graph SLAM.

    The logs scored are those of ``candidates`` (default: every public log in the stores) on which some run has
    a number of the ``scoring``.
    """
    deg = scoring.degradation
    section = Section(
        "experiment-6",
        "Experiment 6: a dataset from the SLAM community (3.2.6)",
        "On a public log (Figure 3.29; the log is not named) Albot1 computes a map of reasonable shape, shown "
        "beside GMapping's. The thesis gives no number.",
        "Every public log of the default suite with ground-truth relations, scored with the relation metric of "
        "Kuemmerle et al. (2009) as the standard benchmark scores it (docs/metrics.md). We read 'reasonable "
        "shape' as a relation error below the raw odometry's (the map Albot1 starts from), by a paired test: "
        f"the two runs' errors on the same relations, a {CONFIDENCE:.0%} paired block-bootstrap interval of the "
        "ratio of their means entirely below 1 (`albot1/metrics/paired.py`); the RBPF (`mrpt-rbpf`, "
        "run by the default suite on the standard logs where it fits its budget) and graph (`gtsam-graph`) "
        "baselines are shown beside it, without a verdict: the thesis made no claim about them here.",
    )
    considered = [d for d in ev.datasets() if is_public(d)] if candidates is None else list(candidates)
    datasets = [
        d
        for d in considered
        if any(number(ev, d, m, scoring.metres, "", "", deg).known for m in (*VARIANTS, ODOMETRY, *EXP6_BASELINES))
    ]
    for dataset in datasets:
        section.claims.append(
            ClaimRow(
                "a map of reasonable shape (relation error below the odometry's)",
                "a map in reasonable shape (3.2.6, Figure 3.29b; no number)",
                per_variant(VARIANTS, partial(_reasonable_shape, ev, scoring, dataset)),
                dataset=dataset,
            )
        )
    methods = [ODOMETRY, *VARIANTS, *EXP6_BASELINES]
    rows = []
    missing: list[str] = []  # why a table cell reads n/a: a diverged baseline is not a missing number
    for dataset in datasets:
        used = next(
            (n for m in methods if (n := number(ev, dataset, m, scoring.count, "", "", deg)).known),
            Number("relations", None),
        )
        row = [f"`{dataset}`", store_of(ev, dataset, methods, deg), used.text()]
        for m in methods:
            metres = number(ev, dataset, m, scoring.metres, "", "m", deg)
            degrees = number(ev, dataset, m, scoring.degrees, "", "deg", deg)
            row.append(tagged(f"{cell(metres)} / {cell(degrees)}", metres, degrees))
            if not metres.known:
                missing.append(f"`{m}` on `{dataset}`: {metres.missing or 'no value'}")
        rows.append(row)
    if rows:
        section.tables.append(
            "Relation metric, mean translational / rotational error over the relations inside the run:\n\n"
            + table(["dataset", "store", "relations", *methods], rows)
        )
        if missing:
            section.notes.append("Why a cell of the relation table reads n/a: " + "; ".join(missing) + ".")
    else:
        section.notes.append(
            "No public log with ground-truth relations has results in the stores read (run the default suite "
            "with the public datasets: `make bench`)."
        )
    published = published_relations(d for d in datasets if d in catalog.names())
    if published is not None:
        section.tables.append(published)
    for dataset in datasets:
        section.figures.append(
            FigureRequest(
                "maps",
                f"exp6-maps-{dataset}",
                f"Figure 3.29 style: `{dataset}`, Albot1 beside the RBPF and graph baselines",
                dataset,
                (*VARIANTS, "mrpt-rbpf", "gtsam-graph"),
            )
        )
    return section
