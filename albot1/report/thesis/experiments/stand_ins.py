"""The page's table of what stands in for the thesis's data, with the stand-ins' sizes measured from the stores."""

from __future__ import annotations

from collections.abc import Iterable

from albot1.report.thesis.claims import THESIS
from albot1.report.thesis.evidence import Evidence
from albot1.report.thesis.experiments.common import (
    LOOP_GAP,
    ODOMETRY,
    PLACES_VARIANTS,
    ROUTE,
    VARIANTS,
    VIEWS,
    number,
)
from albot1.report.thesis.experiments.datasets import thesis_datasets


def _facts(ev: Evidence, dataset: str, methods: Iterable[str]) -> str:
    """``96.0 m, 106 views`` of the first of ``methods`` with a run on ``dataset`` (measured, from its metrics)."""
    for method in methods:
        route = number(ev, dataset, method, ROUTE, "route", "m")
        if route.known:
            views = number(ev, dataset, method, VIEWS, "views", "views")
            return f"{route.text()}, {views.text()}"
    return "not run"


def stand_ins(ev: Evidence) -> list[str]:
    """The table of what stands in for the thesis's data, the stand-ins' sizes measured from the stores."""
    ds = thesis_datasets()
    everyone = (ODOMETRY, *VARIANTS, *PLACES_VARIANTS)
    gap = number(ev, ds.square, ODOMETRY, LOOP_GAP, "odometry loop gap", "m")
    places = "; ".join(
        f"`{d}`: {_facts(ev, d, everyone)}" for d in (*ds.places_starts[:1], ds.double_loop, ds.two_laps)
    )
    return [
        "## What stands in for the thesis's data",
        "",
        "The thesis's own logs (its Pioneer 3-DX in the AUT office, Figures 3.3, 3.20, 3.23, 4.1, 4.4) are not "
        "available. These stand in for them (route lengths and view counts measured from the stored runs):",
        "",
        "| thesis | stand-in | why |",
        "|---|---|---|",
        "| Experiments 1-2: six start-stop routes through the office; four stops measured on the floor plan "
        "(3.2.1-3.2.2) | the square and office worlds of this suite; every public log of the default suite "
        "(reference poses from the SLAM-corrected logs) | exact ground truth on the worlds; real sensors on the "
        "logs |",
        f"| Experiment 3: a square-like route of about {THESIS['exp3_route_m'].text()}, {THESIS['exp3_views'].text()}, "
        f"odometry gap {THESIS['exp3_odometry_gap_m'].text()} (3.2.3) | `{ds.square}`: "
        f"{_facts(ev, ds.square, everyone)}, "
        f"odometry gap {gap.text()} | the same route shape and odometry drift, so the gaps compare like for like |",
        f"| Experiments 4-5: a {THESIS['exp4_route_m'].text()} route as {THESIS['exp4_views'].text()} (10 cm / "
        f"1 deg) and {THESIS['exp5_views'].text()} (1 m / 10 deg) (3.2.4-3.2.5) | `{ds.dense}` "
        f"({_facts(ev, ds.dense, everyone)}) and `{ds.sparse}` ({_facts(ev, ds.sparse, everyone)}) | one route at both "
        "spacings, as in the thesis |",
        "| Experiment 5's SLAM systems: DP-SLAM, CARMEN's mapper, GMapping, gridSLAM | `mrpt-rbpf` (RBPF, the "
        "GMapping/gridSLAM family), `mrpt-icp` (scan matching, as CARMEN's mapper), `kiss-icp`, `gtsam-graph`; "
        "DP-SLAM has no implementation (published figures only) | the field's maintained implementations |",
        "| Experiment 6: an unnamed public log with odometry and laser (3.2.6) | the public logs of the default "
        "suite with ground-truth relations (Radish) | the standard benchmark of the SLAM community |",
        "| Chapter 4: a loop of about 90 m through six places from three starts, a 150 m double loop, the loop "
        f"repeated (4.2.1-4.2.3) | the six-room worlds: {places} | room labels give the true re-visits and "
        "doorways the true exits |",
        "",
    ]
