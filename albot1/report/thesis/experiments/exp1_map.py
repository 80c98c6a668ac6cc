"""Experiment 1 (3.2.1): the map keeps the shape of the environment; it is not updated for every view."""

from __future__ import annotations

from functools import partial

from albot1.report.thesis.claims import READINGS
from albot1.report.thesis.evidence import Evidence
from albot1.report.thesis.experiments.common import (
    ODOMETRY,
    PER_VIEW,
    SHAPE,
    UPDATES,
    VARIANTS,
    VIEWS,
    ClaimRow,
    FigureRequest,
    Section,
    albot1_datasets,
    cell,
    is_public,
    lacks_reference,
    number,
    per_variant,
    shape_cell,
    shape_kept,
    store_of,
    table,
    tagged,
)
from albot1.report.thesis.experiments.datasets import thesis_datasets
from albot1.report.thesis.verdicts import (
    Number,
    Verdict,
    at_most,
)


def _not_every_view(ev: Evidence, dataset: str, method: str) -> Verdict:
    return at_most(number(ev, dataset, method, PER_VIEW, f"{method} updates/view"), 1.0, strict=True)


def section_map(ev: Evidence) -> Section:
    """Experiment 1 (3.2.1): the map keeps the environment's overall shape; it is not updated for every view."""
    ds = thesis_datasets()
    shape = READINGS["shape_median_m"]
    section = Section(
        "experiment-1",
        "Experiment 1: the map computed (3.2.1)",
        "All maps of six routes through the office keep the overall shape of the environment traversed "
        "(Figures 3.14-3.15, judged by eye); the map is updated when the robot leaves a local environment, "
        "not for every view (Figure 3.17: the map after each update; 3.3).",
        "The thesis's logs are not available. Stand-ins: the 96 m square start-stop world and the office loop at "
        "two view spacings, and every dataset of the default suite (its `albot1:thesis` runs are read from "
        "`results/default`; the literal reading and Albot1+ run in this suite). Logs with reference poses get a "
        "map-shape number; raw logs without them cannot.",
    )
    datasets = albot1_datasets(ev, VARIANTS)
    without = [d for d in datasets if lacks_reference(ev, d, VARIANTS, SHAPE)]
    with_shape = [d for d in datasets if d not in without]
    for dataset in with_shape:
        section.claims.append(
            ClaimRow(
                f"the map keeps the overall shape (half of it within {shape.value:g} m of a true wall)",
                "all maps keep the shape (3.2.1, Figures 3.14-3.15; judged by eye)",
                per_variant(VARIANTS, partial(shape_kept, ev, dataset)),
                dataset=dataset,
            )
        )
    for dataset in datasets:
        section.claims.append(
            ClaimRow(
                "the map is not updated for every view (updates per view < 1)",
                "updates only on leaving a local environment (3.2.1, Figure 3.17; 3.3)",
                per_variant(VARIANTS, partial(_not_every_view, ev, dataset)),
                dataset=dataset,
            )
        )
    if without:
        section.notes.append(
            "No map-shape number (no reference poses to build the true map from), so only the update claim is "
            "tested on: " + ", ".join(f"`{d}`" for d in without) + "."
        )
    rows = []
    for dataset in datasets:
        views = next(
            (n for m in VARIANTS if (n := number(ev, dataset, m, VIEWS, "views")).known), Number("views", None)
        )
        row = [f"`{dataset}`", store_of(ev, dataset, [*VARIANTS, ODOMETRY]), views.text()]
        for method in VARIANTS:
            updates, per_view = number(ev, dataset, method, UPDATES, ""), number(ev, dataset, method, PER_VIEW, "")
            row += [tagged(f"{cell(updates)} ({cell(per_view)})", updates, per_view), shape_cell(ev, dataset, method)]
        row.append(shape_cell(ev, dataset, ODOMETRY))
        rows.append(row)
    header = ["dataset", "store", "views"]
    for method in VARIANTS:
        header += [f"{method} updates (per view)", f"{method} map: median / precision"]
    header.append("odometry map: median / precision")
    section.tables.append(
        "Measured (map: median distance of the map to the true walls / precision, the fraction within the "
        "map-shape tolerance; `n/a` without reference poses):\n\n" + table(header, rows)
    )
    section.figures.append(
        FigureRequest(
            "trace",
            "exp1-trace",
            "Figure 3.17 style: the map after each update and which views triggered one",
            ds.square,
            tuple(VARIANTS),
        )
    )
    section.figures.append(
        FigureRequest(
            "animation", "exp1-animation", "the perceptual map along the route", ds.square, ("albot1:thesis",)
        )
    )
    # One public log is drawn here with the three variants and animated (a replay of a public log costs seconds);
    # every other dataset's maps, with every method, are the default suite's report figures, linked.
    public = [d for d in with_shape if is_public(d) and number(ev, d, "albot1:thesis", SHAPE, "").known]
    drawn = [ds.square, *public[:1]]
    for dataset in drawn:
        section.figures.append(
            FigureRequest(
                "maps",
                f"exp1-maps-{dataset}",
                f"maps of `{dataset}` (Albot1 variants and dead reckoning)",
                dataset,
                (ODOMETRY, *VARIANTS),
            )
        )
    if public:
        section.figures.append(
            FigureRequest(
                "animation",
                "exp1-animation-public",
                "the perceptual map along a public log",
                public[0],
                ("albot1:thesis",),
            )
        )
    measured = [d for d in with_shape if any(number(ev, d, m, SHAPE, m).known for m in VARIANTS)]
    for dataset in measured:
        if dataset not in drawn and dataset not in (ds.dense, ds.sparse):  # those two: Experiments 4-5's figures
            section.figures.append(
                FigureRequest("linked-maps", f"exp1-maps-{dataset}", f"maps of `{dataset}` (default suite)", dataset)
            )
    return section
