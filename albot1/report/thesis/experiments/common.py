"""What every experiment of the thesis page is made of: the section model, the method labels, the metric
paths and the helpers that read a number, test it per Albot1 variant and lay out a table.

Nothing here formats a verdict by hand: every word comes from :mod:`albot1.report.thesis.verdicts`
given numbers read from ``metrics.json`` files.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from albot1.metrics.unit import NO_REFERENCE
from albot1.report.thesis.claims import READINGS, THESIS
from albot1.report.thesis.evidence import Evidence, Lookup, counter_path, seeds_of
from albot1.report.thesis.verdicts import Number, Verdict, at_most, held
from albot1.report.tuning import marked

#: The Albot1 variants every claim is tested for: label -> column heading.
VARIANTS: dict[str, str] = {
    "albot1:literal": "literal reading",
    "albot1:thesis": "thesis preset",
    "albot1:plus": "Albot1+",
}
#: The same three for chapter 4 (Albot1 with its network of places).
PLACES_VARIANTS: dict[str, str] = {
    "albot1-places:literal": "literal reading",
    "albot1-places:thesis": "thesis preset",
    "albot1-places:plus": "Albot1+",
}
ODOMETRY = "odometry"
#: The SLAM baselines of Experiments 5 and 6 (the thesis's particle filters and scan matchers, and a graph).
SLAM_BASELINES = ("kiss-icp", "gtsam-graph", "mrpt-icp", "mrpt-rbpf")
#: Experiment 6's RBPF and graph baselines.
EXP6_BASELINES = ("mrpt-rbpf", "gtsam-graph", "mrpt-icp", "kiss-icp")

# metrics.json paths
LOOP_GAP = "loop_gap.route.gap_m"
PRECISION = "map_shape.precision"
COVERAGE = "map_shape.coverage"
SHAPE = "map_shape.map_to_reference_median_m"
VIEWS = "updates.views"
UPDATES = "updates.updates"
PER_VIEW = "updates.updates_per_view"
ATE = "ate.rmse_m"
ROUTE = "drift.route_m"
STOPS = "orientation.stops"
RELATION_M = "relations.translation_m.mean"
RELATION_DEG = "relations.rotation_deg.mean"
RELATIONS_USED = "relations.relations_used"


def counter(name: str) -> str:
    """The metrics.json path of a mapper counter (``updates.counters.NAME``), or of the places metric's judgement."""
    return counter_path(name)


@dataclass(frozen=True)
class ClaimRow:
    """One claim, tested on one dataset (or on the experiment's), the thesis's side and a verdict per variant.

    ``verdicts`` maps each variant's label to its verdict, or ``""`` to one verdict for all (a check of the
    stand-in data, not of Albot1). Rows of one claim on several datasets share ``claim`` and differ in
    ``dataset``, so the page can count them.
    """

    claim: str
    thesis: str
    verdicts: dict[str, Verdict]
    dataset: str = ""

    @property
    def text(self) -> str:
        return f"`{self.dataset}`: {self.claim}" if self.dataset else self.claim


@dataclass(frozen=True)
class FigureRequest:
    """A figure the page should draw: its kind, file stem, caption and what it is drawn from."""

    kind: str  # "trace" | "animation" | "maps" | "linked-maps" | "gap-maps" | "places"
    stem: str
    caption: str
    dataset: str = ""
    methods: tuple[str, ...] = ()
    degradations: tuple[str, ...] = ("none",)


@dataclass
class Section:
    """One experiment on the page."""

    anchor: str
    title: str
    thesis_says: str
    stand_in: str
    claims: list[ClaimRow] = field(default_factory=list)
    tables: list[str] = field(default_factory=list)
    figures: list[FigureRequest] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    columns: dict[str, str] = field(default_factory=lambda: dict(VARIANTS))

    def claim_groups(self) -> list[tuple[str, list[ClaimRow]]]:
        """The claims' rows grouped by claim (first-seen order), each with its label for a summary row.

        A claim tested on one dataset keeps its own text; one tested on
        several reads "<claim> (on each dataset)". The thesis page's summary
        and the results page count verdicts over the same groups.
        """
        groups: dict[str, list[ClaimRow]] = {}
        for row in self.claims:
            groups.setdefault(row.claim, []).append(row)
        return [
            (rows[0].text if len(rows) == 1 else f"{claim} (on each dataset)", rows) for claim, rows in groups.items()
        ]


# --------------------------------------------------------------------------- reading and laying out numbers


def number(ev: Evidence, dataset: str, method: str, path: str, label: str, unit: str = "", deg: str = "none") -> Number:
    """The number at ``path`` of ``method``'s run on ``dataset`` (degradation ``deg``), or why it is missing."""
    return ev.number(ev.find(dataset, method, deg), path, label, unit)


def cell(value: Number) -> str:
    """A table cell: the number with its unit, or ``n/a`` (a cell of a run's numbers: :func:`tagged`)."""
    return value.text()


def tagged(text: str, *numbers: Number) -> str:
    """A table cell ``text`` showing ``numbers`` of one run, with the held-in mark once when they are held-in.

    Once per cell, not per number: ``0.227 m / 0.566 †`` reads as one run's pair, and counts of the same run
    (views, stops) need no mark of their own.
    """
    return marked(text, held(*(n for n in numbers if n.known)))


def store_of(ev: Evidence, dataset: str, methods: Iterable[str], deg: str = "none") -> str:
    """The stores the runs of ``methods`` on ``dataset`` were read from (every number names its store).

    A store that ran several seeds there also names the one its numbers are read at (:func:`compared_seed`,
    the same for every method), so a verdict says which randomness it compared.
    """
    stores: dict[str, None] = {}
    for method in methods:
        found: Lookup = ev.find(dataset, method, deg)
        if found.store is not None and found.record is not None:
            seeds = sorted(seeds_of(found.store.records, dataset, deg))
            planned = ", ".join(map(str, seeds))
            at = f" (seed {found.record.cell.seed} of seeds {planned})" if len(seeds) > 1 else ""
            stores[f"`{found.store.path}`{at}"] = None
    return ", ".join(stores) or "–"


def table(header: list[str], rows: list[list[str]]) -> str:
    """A Markdown table (a ``|`` inside a cell is escaped)."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(text.replace("|", "\\|") for text in row) + " |" for row in rows]
    return "\n".join(lines)


def per_variant(variants: dict[str, str], test: Callable[[str], Verdict]) -> dict[str, Verdict]:
    """One verdict per variant label."""
    return {label: test(label) for label in variants}


def thesis_text(key: str) -> str:
    """A number of the thesis with its source, e.g. ``4.6 m (3.2.3, Figure 3.21)``."""
    published = THESIS[key]
    return f"{published.text()} ({published.source})"


def albot1_datasets(ev: Evidence, variants: Iterable[str]) -> list[str]:
    """The datasets on which any of ``variants`` was planned, in plan order."""
    wanted = set(variants)
    return [d for d in ev.datasets() if any(m in wanted for m in ev.methods(d))]


def lacks_reference(ev: Evidence, dataset: str, methods: Iterable[str], path: str) -> bool:
    """Whether the metric at ``path`` does not apply to ``dataset`` because the dataset has no reference poses.

    Why: a claim measured against reference poses is left out on such a dataset (a note says so), but on
    no other ground. A dataset whose runs failed, did not run yet or lack the number for another reason
    keeps its claim row, and its verdicts say "not comparable" with that reason; leaving it out would
    drop the claim from the count and blame the dataset for the runs. True when no run of ``methods``
    has the number and a run says the dataset has no reference poses (the metric's own words).
    """
    numbers = [number(ev, dataset, method, path, method) for method in methods]
    return not any(n.known for n in numbers) and any(n.missing == NO_REFERENCE for n in numbers)


def is_public(dataset: str) -> bool:
    """Whether ``dataset`` is a public log (not one of the synthetic worlds)."""
    return not dataset.startswith("synthetic-")


# --------------------------------------------------------------------------- shared claim tests


def shape_kept(ev: Evidence, dataset: str, method: str) -> Verdict:
    """The map keeps the overall shape: its median distance to the true walls is within the reading."""
    shape = number(ev, dataset, method, SHAPE, f"{method} median map-to-wall", "m")
    return at_most(shape, READINGS["shape_median_m"].value)


def shape_cell(ev: Evidence, dataset: str, method: str) -> str:
    """``median / precision`` of a run's map (held-in marked, :func:`tagged`)."""
    median, precision = number(ev, dataset, method, SHAPE, "", "m"), number(ev, dataset, method, PRECISION, "")
    return tagged(f"{cell(median)} / {cell(precision)}", median, precision)
