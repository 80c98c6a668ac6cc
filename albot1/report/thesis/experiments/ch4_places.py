"""Chapter 4 (4.2.1-4.2.3): places learned, re-visits recognised, exit predictions aligned vs not."""

from __future__ import annotations

from functools import partial

from albot1.report.thesis.claims import THESIS
from albot1.report.thesis.evidence import Evidence
from albot1.report.thesis.experiments.common import (
    PLACES_VARIANTS,
    ClaimRow,
    FigureRequest,
    Section,
    cell,
    counter,
    number,
    per_variant,
    store_of,
    table,
    tagged,
)
from albot1.report.thesis.experiments.datasets import thesis_datasets
from albot1.report.thesis.verdicts import (
    Verdict,
    all_of,
    at_least,
    equals,
    lower_than,
)


def _aligned_nearer(ev: Evidence, dataset: str, suffix: str, method: str) -> Verdict:
    """Aligned exit predictions are nearer (``suffix`` ``_true``: the true doorway) than unaligned ones."""
    return lower_than(
        number(ev, dataset, method, counter(f"exit_prediction_aligned{suffix}_mean_m"), f"{method} aligned", "m"),
        number(ev, dataset, method, counter(f"exit_prediction_not_aligned{suffix}_mean_m"), "not aligned", "m"),
    )


def section_places(ev: Evidence) -> Section:
    """Chapter 4 (4.2.1-4.2.3): places learned, re-visits recognised, exits predicted aligned vs not."""
    ds = thesis_datasets()
    places = THESIS["places_single_loop"]
    loop, *starts = ds.places_starts  # the other start points and the two laps are options of the loop's world
    variants = ", ".join(f"`{label.removeprefix(loop)}`" for label in starts)
    section = Section(
        "chapter-4",
        "Chapter 4: places (4.2.1-4.2.3)",
        f"On a single loop crossing six exits Albot1 learns {places.text()} and recognises the start place on "
        f"return, from each of three start points ({places.source}, Figure 4.3). On a double loop it misses one "
        "re-visit (a new place P7 is created) but recognises P2 and P1 later, and never confuses two places "
        "(4.2.2, Figure 4.5). Exits of a re-visited place brought into the perceptual map and aligned at the "
        "exit just crossed predict the exits ahead better than unaligned ones (4.2.3, Figure 4.8; no number).",
        f"The six-room worlds (docs/synthetic-worlds.md): `{loop}` from S, A and B ({variants}), "
        f"`{ds.double_loop}` (a second loop entering room 5 from a new side) and the loop driven twice "
        f"(`{ds.two_laps.removeprefix(loop)}`) for the exit predictions. Re-visits are judged against the rooms "
        "the reference poses were in (docs/places.md); precision = true claimed re-visits / claims, recall = "
        "recognised / actual re-visits. Exit-prediction error: distance of a predicted exit's midpoint from the exit "
        "perceived (Figure 4.8's measure) and from the true doorway.",
        columns=dict(PLACES_VARIANTS),
    )
    for dataset in ds.places_starts:

        def single(m: str, d: str = dataset) -> Verdict:
            return all_of(
                [
                    equals(number(ev, d, m, counter("places"), f"{m} places"), places.value),
                    equals(number(ev, d, m, counter("revisit_recall"), f"{m} re-visit recall"), 1.0),
                    equals(number(ev, d, m, counter("revisit_precision"), f"{m} re-visit precision"), 1.0),
                ]
            )

        section.claims.append(
            ClaimRow(
                f"{places.value:g} places, every re-visit recognised, none claimed wrongly",
                f"{places.text()}, start place recognised (4.2.1, Figures 4.2-4.3)",
                per_variant(PLACES_VARIANTS, single),
                dataset=dataset,
            )
        )

    def double(m: str) -> Verdict:
        return all_of(
            [
                equals(number(ev, ds.double_loop, m, counter("revisit_precision"), f"{m} re-visit precision"), 1.0),
                at_least(
                    number(ev, ds.double_loop, m, counter("revisit_recall"), f"{m} re-visit recall"), 0.0, strict=True
                ),
            ]
        )

    section.claims.append(
        ClaimRow(
            "no place confused with another; some re-visits recognised (misses allowed)",
            "one re-visit missed, P2 and P1 recognised, none wrong (4.2.2, Figure 4.5)",
            per_variant(PLACES_VARIANTS, double),
            dataset=ds.double_loop,
        )
    )
    for suffix, against, source in (
        ("", "the exit perceived", "Figure 4.8's measure"),
        ("_true", "the true doorway", "against ground truth"),
    ):
        section.claims.append(
            ClaimRow(
                f"aligned exit predictions are nearer {against} than unaligned ones ({source})",
                "aligned predictions co-locate with the exits perceived; unaligned ones show the wrong whereabouts "
                "(4.2.3, Figures 4.7-4.8; no number)",
                per_variant(PLACES_VARIANTS, partial(_aligned_nearer, ev, ds.two_laps, suffix)),
                dataset=ds.two_laps,
            )
        )
    rows = []
    for dataset in (*ds.places_starts, ds.double_loop, ds.two_laps):
        row = [f"`{dataset}`", store_of(ev, dataset, PLACES_VARIANTS)]
        for m in PLACES_VARIANTS:
            read = {
                name: number(ev, dataset, m, counter(name), "")
                for name in (
                    "places",
                    "places_created",
                    "revisits_actual",
                    "revisits_true",
                    "revisits_false",
                    "revisits_missed",
                    "revisit_precision",
                    "revisit_recall",
                )
            }
            c = {name: cell(value) for name, value in read.items()}
            text = (
                f"{c['places']} places ({c['places_created']} created); re-visits {c['revisits_actual']}: "
                f"{c['revisits_true']} true / {c['revisits_false']} false / {c['revisits_missed']} missed; "
                f"P {c['revisit_precision']}, R {c['revisit_recall']}"
            )
            row.append(tagged(text, *read.values()))
        rows.append(row)
    section.tables.append(
        "Places and re-visits (thesis: 6 places on the single loop, 4.2.1):\n\n"
        + table(["dataset", "store", *PLACES_VARIANTS], rows)
    )
    rows = []
    for m in PLACES_VARIANTS:
        read_back = [
            number(ev, ds.two_laps, m, counter(name), "", unit)
            for name, unit in (
                ("exit_predictions_compared", ""),
                ("exit_prediction_aligned_mean_m", "m"),
                ("exit_prediction_not_aligned_mean_m", "m"),
                ("exit_prediction_aligned_true_mean_m", "m"),
                ("exit_prediction_not_aligned_true_mean_m", "m"),
            )
        ]
        rows.append([f"`{m}`", *(tagged(cell(value), value) for value in read_back)])
    section.tables.append(
        f"Exit predictions on `{ds.two_laps}` (mean midpoint distance; thesis: Figure 4.8, no numbers in the text):\n\n"
        + table(
            [
                "method",
                "predictions compared",
                "aligned vs perceived",
                "not aligned vs perceived",
                "aligned vs true doorway",
                "not aligned vs true doorway",
            ],
            rows,
        )
    )
    for dataset in (*ds.places_starts, ds.double_loop, ds.two_laps):
        section.figures.append(
            FigureRequest(
                "places",
                f"ch4-places-{dataset}",
                f"Figure 4.2 style: the network of places learnt on `{dataset}` (albot1-places:thesis)",
                dataset,
                ("albot1-places:thesis",),
            )
        )
    return section
