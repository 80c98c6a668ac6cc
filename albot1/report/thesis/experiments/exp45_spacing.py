"""Experiments 4-5 (3.2.4-3.2.5): one route as views 0.1 m / 1 deg and 1 m / 10 deg apart: updates per view,
and every method's map (the thesis's SLAM systems lose the shape on the sparse views).
"""

from __future__ import annotations

from functools import partial

from albot1.report.thesis.claims import READINGS, THESIS
from albot1.report.thesis.evidence import Evidence
from albot1.report.thesis.experiments.common import (
    ATE,
    COVERAGE,
    LOOP_GAP,
    ODOMETRY,
    PER_VIEW,
    PRECISION,
    SHAPE,
    SLAM_BASELINES,
    UPDATES,
    VARIANTS,
    VIEWS,
    ClaimRow,
    FigureRequest,
    Section,
    cell,
    number,
    per_variant,
    shape_kept,
    store_of,
    table,
    tagged,
)
from albot1.report.thesis.experiments.datasets import thesis_datasets
from albot1.report.thesis.experiments.published import published_notes
from albot1.report.thesis.verdicts import (
    Verdict,
    all_of,
    at_least,
    at_most,
    lower_than,
    quantity,
)


def _slam_fails(ev: Evidence, sparse: str, baseline: str, method: str) -> Verdict:
    """On the sparse views (``sparse``) the baseline loses the shape and Albot1's map is nearer the walls than its."""
    theirs = number(ev, sparse, baseline, SHAPE, f"{baseline} median map-to-wall", "m")
    return all_of(
        [
            at_least(theirs, READINGS["shape_median_m"].value, strict=True),
            lower_than(
                number(ev, sparse, method, SHAPE, f"{method} median", "m"),
                number(ev, sparse, baseline, SHAPE, baseline, "m"),
            ),
        ]
    )


def section_spacing(ev: Evidence) -> Section:
    """Experiments 4-5 (3.2.4-3.2.5): one route as dense and sparse views; updates and every method's map."""
    ds = thesis_datasets()
    dense, sparse = READINGS["dense_updates_per_view"], READINGS["sparse_updates_per_view"]
    shape = READINGS["shape_median_m"]
    d_views, d_upd = THESIS["exp4_views"], THESIS["exp4_updates"]
    s_views, s_upd = THESIS["exp5_views"], THESIS["exp5_updates"]
    section = Section(
        "experiments-4-5",
        "Experiments 4-5: continuous movement and fewer views (3.2.4-3.2.5)",
        f"On a {THESIS['exp4_route_m'].text()} route, {d_views.text()} 10 cm / 1 deg apart gave {d_upd.text()} "
        f"({d_upd.source}) and the map kept its shape; the same route as {s_views.text()} 1 m / 10 deg apart gave "
        f"{s_upd.text()} ({s_upd.source}), still a good map, while DP-SLAM, CARMEN's mapper, GMapping and "
        "gridSLAM produced completely distorted maps (Figures 3.26-3.28).",
        f"One route, the office loop: `{ds.dense}` (views 0.1 m / 1 deg apart) and `{ds.sparse}` (the same scans "
        "thinned by the view-spacing option to 1 m / 10 deg, docs/datasets.md). Every installed method runs on both: "
        "MRPT's `rbpf-slam` stands in for the particle filters (GMapping, gridSLAM), `icp-slam` for CARMEN's "
        "scan-matching mapper, plus KISS-ICP and the GTSAM pose graph.",
    )
    section.claims.append(
        ClaimRow(
            f"views 0.1 m / 1 deg apart: updates for at most {dense.value:g} of the views",
            f"{d_upd.value:g}/{d_views.value:g} = {quantity(d_upd.value / d_views.value)} ({d_upd.source})",
            per_variant(
                VARIANTS, lambda m: at_most(number(ev, ds.dense, m, PER_VIEW, f"{m} updates/view"), dense.value)
            ),
        )
    )
    section.claims.append(
        ClaimRow(
            "views 1 m / 10 deg apart: fewer updates than views",
            f"{s_upd.value:g}/{s_views.value:g} = {quantity(s_upd.value / s_views.value)} ({s_upd.source})",
            per_variant(
                VARIANTS,
                lambda m: at_most(number(ev, ds.sparse, m, PER_VIEW, f"{m} updates/view"), sparse.value, strict=True),
            ),
        )
    )
    for dataset, what in ((ds.dense, "0.1 m / 1 deg"), (ds.sparse, "1 m / 10 deg")):
        section.claims.append(
            ClaimRow(
                f"views {what} apart: Albot1's map keeps the shape (half of it within {shape.value:g} m of a "
                "true wall)",
                "the overall shape is preserved (Figures 3.24b, 3.26b; judged by eye)",
                per_variant(VARIANTS, partial(shape_kept, ev, dataset)),
            )
        )
    for baseline in SLAM_BASELINES:
        section.claims.append(
            ClaimRow(
                f"views 1 m / 10 deg apart: `{baseline}` loses the shape (median map-to-wall over {shape.value:g} m) "
                "where Albot1's is nearer the walls",
                "every SLAM method's map is completely distorted (3.2.5, Figures 3.27-3.28)",
                per_variant(VARIANTS, partial(_slam_fails, ev, ds.sparse, baseline)),
            )
        )
    rows = []
    for dataset, views, updates in ((ds.dense, d_views, d_upd), (ds.sparse, s_views, s_upd)):
        row = [f"`{dataset}`", cell(number(ev, dataset, "albot1:thesis", VIEWS, "")), views.text()]
        for m in VARIANTS:
            updates_m, per_view = number(ev, dataset, m, UPDATES, ""), number(ev, dataset, m, PER_VIEW, "")
            row.append(tagged(f"{cell(updates_m)} ({cell(per_view)})", updates_m, per_view))
        row.append(f"{updates.value:g} ({quantity(updates.value / views.value)})")
        rows.append(row)
    section.tables.append(
        "Updates (per view):\n\n"
        + table(["dataset", "views", "thesis: views", *VARIANTS, "thesis: updates (per view)"], rows)
    )
    methods = [ODOMETRY, *VARIANTS, *SLAM_BASELINES]
    rows = []
    for method in methods:
        row = [f"`{method}`"]
        for dataset in (ds.dense, ds.sparse):
            shown = [
                number(ev, dataset, method, SHAPE, "", "m"),
                number(ev, dataset, method, PRECISION, ""),
                number(ev, dataset, method, COVERAGE, ""),
                number(ev, dataset, method, ATE, "", "m"),
                number(ev, dataset, method, LOOP_GAP, "", "m"),
            ]
            row += [tagged(cell(value), value) for value in shown]
        rows.append(row)
    header = ["method"]
    for what in ("0.1 m / 1 deg", "1 m / 10 deg"):
        header += [f"{what}: median map-to-wall", f"{what}: precision", f"{what}: coverage", f"{what}: ATE"]
        header.append(f"{what}: loop gap")
    section.tables.append(
        f"Every method on both spacings (store {store_of(ev, ds.dense, methods)}; `n/a`: the method did not run, "
        "see the verdicts for why):\n\n" + table(header, rows)
    )
    section.notes += published_notes(("dp-slam",))
    for dataset, what in (
        (ds.dense, "0.1 m / 1 deg (Figure 3.24, 3.25)"),
        (ds.sparse, "1 m / 10 deg (Figures 3.26-3.28)"),
    ):
        section.figures.append(
            FigureRequest("maps", f"exp45-maps-{dataset}", f"every method's map, views {what}", dataset, tuple(methods))
        )
    return section
