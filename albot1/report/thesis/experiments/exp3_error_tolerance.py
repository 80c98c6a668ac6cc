"""Experiment 3 (3.2.3): the loop gap of odometry and Albot1 on a square start-stop route, clean and with
the thesis's induced error (+0.1 m and +1 deg per step).
"""

from __future__ import annotations

from albot1.report.thesis.claims import READINGS, THESIS
from albot1.report.thesis.evidence import Evidence
from albot1.report.thesis.experiments.common import (
    LOOP_GAP,
    ODOMETRY,
    ROUTE,
    VARIANTS,
    VIEWS,
    ClaimRow,
    FigureRequest,
    Section,
    cell,
    number,
    per_variant,
    store_of,
    table,
    tagged,
    thesis_text,
)
from albot1.report.thesis.experiments.datasets import thesis_datasets
from albot1.report.thesis.verdicts import (
    Verdict,
    close_to,
    quantity,
    ratio_at_least,
)


def section_error_tolerance(ev: Evidence) -> Section:
    """Experiment 3 (3.2.3): loop gap of odometry vs Albot1, clean and with +0.1 m / +1 deg per step."""
    ds = thesis_datasets()
    ratio, tolerance = READINGS["gap_ratio"], READINGS["setup_tolerance"]
    odo_clean, odo_induced = THESIS["exp3_odometry_gap_m"], THESIS["exp3_odometry_gap_induced_m"]
    alb_clean, alb_induced = THESIS["exp3_albot1_gap_m"], THESIS["exp3_albot1_gap_induced_m"]
    section = Section(
        "experiment-3",
        "Experiment 3: error tolerance (3.2.3)",
        f"On a square-like route of about {THESIS['exp3_route_m'].text()} ({THESIS['exp3_views'].text()}, "
        f"start-stop) the odometry map's loop gap is {odo_clean.text()} and Albot1's {alb_clean.text()} "
        f"({odo_clean.source}, {alb_clean.source}); with +0.1 m and +1 deg added per step, {odo_induced.text()} "
        f"and {alb_induced.text()} ({odo_induced.source}, {alb_induced.source}).",
        f"`{ds.square}`: a 96 m square corridor ring driven start-stop (1 m / 45 deg), whose simulated odometry "
        "(the office worlds' error model, docs/synthetic-worlds.md) ends 4.6 m from its start, so both rows are "
        f"compared like for like. The induced error is the `{ds.induced}` degradation (+0.1 m and +1 deg on every "
        "step's odometry). Loop gap: distance between the estimated start and end of the closed route.",
    )
    views = number(ev, ds.square, ODOMETRY, VIEWS, "views")
    route = number(ev, ds.square, ODOMETRY, ROUTE, "route", "m")
    section.notes.append(
        f"Stand-in route: {route.text()} and {views.text()} views (thesis: about {THESIS['exp3_route_m'].text()}, "
        f"{THESIS['exp3_views'].text()})."
    )
    section.claims.append(
        ClaimRow(
            "setup: the stand-in's clean odometry reproduces the thesis's odometry gap",
            thesis_text("exp3_odometry_gap_m"),
            {
                "": close_to(
                    number(ev, ds.square, ODOMETRY, LOOP_GAP, "odometry loop gap", "m"),
                    odo_clean.value,
                    tolerance.value,
                )
            },
        )
    )
    section.claims.append(
        ClaimRow(
            "setup: with the induced error the odometry gap matches the thesis's",
            thesis_text("exp3_odometry_gap_induced_m"),
            {
                "": close_to(
                    number(ev, ds.square, ODOMETRY, LOOP_GAP, "odometry loop gap", "m", ds.induced),
                    odo_induced.value,
                    tolerance.value,
                )
            },
        )
    )
    for deg, odo, alb, what in (
        ("none", odo_clean, alb_clean, "clean odometry"),
        (ds.induced, odo_induced, alb_induced, "with +0.1 m / +1 deg per step"),
    ):
        thesis = f"{alb.text()} vs {odo.text()}, {quantity(odo.value / alb.value)}x"

        def test(m: str, deg: str = deg, thesis: str = thesis) -> Verdict:
            return ratio_at_least(
                number(ev, ds.square, m, LOOP_GAP, f"{m} loop gap", "m", deg),
                number(ev, ds.square, ODOMETRY, LOOP_GAP, "odometry", "m", deg),
                ratio.value,
                thesis=thesis,
            )

        section.claims.append(
            ClaimRow(
                f"{what}: Albot1's loop gap is at least {ratio.value:g}x below the odometry's",
                f"{thesis} ({alb.source})",
                per_variant(VARIANTS, test),
            )
        )
    rows = []
    for deg, odo, alb in (("none", odo_clean, alb_clean), (ds.induced, odo_induced, alb_induced)):
        row = [f"`{deg}`", cell(number(ev, ds.square, ODOMETRY, LOOP_GAP, "", "m", deg)), odo.text()]
        gaps = [number(ev, ds.square, m, LOOP_GAP, "", "m", deg) for m in VARIANTS]
        row += [tagged(cell(gap), gap) for gap in gaps]
        row.append(alb.text())
        rows.append(row)
    section.tables.append(
        f"Loop gap on `{ds.square}` (store {store_of(ev, ds.square, [ODOMETRY, *VARIANTS])}):\n\n"
        + table(
            ["odometry degradation", "odometry", "thesis: odometry", *VARIANTS, "thesis: Albot1"],
            rows,
        )
    )
    section.figures.append(
        FigureRequest(
            "gap-maps",
            "exp3-gap-maps",
            "Figures 3.21-3.22 style: maps from the start, the loop gap in green (top: clean odometry; bottom: "
            "+0.1 m / +1 deg per step)",
            ds.square,
            (ODOMETRY, *VARIANTS),
            ("none", ds.induced),
        )
    )
    return section
