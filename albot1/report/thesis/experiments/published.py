"""Published-only systems on the page: why a system is not run (DP-SLAM), and published relation errors.

Their figures are the published ones (``albot1/methods/baselines/published.toml``), labelled as such and never
mixed with the numbers measured here. Experiments 4-5 and 6 use them.
"""

from __future__ import annotations

from collections.abc import Iterable

from albot1.methods.baselines.published import published_systems
from albot1.report.thesis.experiments.common import table


def published_notes(systems: Iterable[str]) -> list[str]:
    """Why each named published-only system (DP-SLAM) is not run, and whether it has published figures."""
    lines = []
    for system in published_systems():
        if system.name in systems:
            figures = "; ".join(f"{f.log} {f.metric} {f.text()} ({f.source})" for f in system.figures)
            lines.append(
                f"{system.label} is not run here: {system.implementation} Published figures: "
                f"{figures or 'none verifiable on these logs'}."
            )
    return lines


def published_relations(logs: Iterable[str]) -> str | None:
    """A table of the published relation errors on ``logs`` (whole logs), labelled published; None if none.

    Each figure reads as its source prints it, mean ± std with the source's decimals (``PublishedFigure.text``):
    ``:g`` would turn the published 0.220 m into 0.22 and leave out the spread.
    """
    rows = []
    wanted = list(logs)
    for system in published_systems():
        for log in wanted:
            figures = {f.metric: f for f in system.figures if f.log == log}
            trans, rot = figures.get("relation_translation_m"), figures.get("relation_rotation_deg")
            if trans is None and rot is None:
                continue
            rows.append(
                [
                    f"`{log}`",
                    system.label,
                    f"{trans.text()} m" if trans else "–",
                    f"{rot.text()} deg" if rot else "–",
                    "; ".join(dict.fromkeys(f.source for f in (trans, rot) if f is not None)),
                ]
            )
    if not rows:
        return None
    return (
        "Published relation errors on the same whole logs (published, not measured here; "
        "`albot1/methods/baselines/published.toml`):\n\n"
        + table(
            [
                "log",
                "published system",
                "published: translation, mean ± std",
                "published: rotation, mean ± std",
                "source",
            ],
            rows,
        )
    )
