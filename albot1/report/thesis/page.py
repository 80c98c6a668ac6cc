"""Write ``reports/thesis/README.md``: the thesis's experiments, its numbers beside ours, computed verdicts.

Called by :func:`albot1.report.index.build_report` for the ``thesis``
suite's results (``albot1 report results/thesis``, ``make bench``). The
page is built from the stores alone (:mod:`albot1.report.thesis.evidence`):
the verdicts from their numbers, the figures from their run folders. A
figure that cannot be drawn (a run that failed, a dataset not available for
a replay) is replaced by the reason; only drawn figures are linked, so every
link of the page resolves. The maps figures of the public logs are the
default report's (``reports/default/plots``): which of them that report
draws is known from its store, so the page links them whether that report
is built before, while or after this one (`make bench` builds them at once);
the links resolve once it is built.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from albot1.errors import Albot1Error
from albot1.metrics.measures.map_shape import METRIC as MAP_SHAPE
from albot1.metrics.measures.orientation import METRIC as ORIENTATION
from albot1.report.collect import CellRecord, as_of
from albot1.report.errors import ReportError
from albot1.report.figure_cache import FigureCache, clear_figures, inputs_digest
from albot1.report.html import rel
from albot1.report.map_plots import maps_drawn, plot_maps
from albot1.report.markdown import text as md_text
from albot1.report.places_plot import render_places
from albot1.report.plots import method_colors, slug, vector_of
from albot1.report.provenance import data_lines
from albot1.report.thesis.claims import READINGS
from albot1.report.thesis.evidence import COMPANION_SUITES, Evidence, open_stores
from albot1.report.thesis.experiments import (
    ClaimRow,
    FigureRequest,
    Section,
    all_sections,
    stand_ins,
    thesis_datasets,
)
from albot1.report.thesis.experiments.common import LOOP_GAP
from albot1.report.thesis.experiments.datasets import THESIS_SUITE  # the suite whose report gets this page
from albot1.report.thesis.figures import animate_map, plot_gap_maps, plot_trace_strip, plot_update_trace
from albot1.report.thesis.replay import Replay, replay_run
from albot1.report.thesis.verdicts import FAILS, HOLDS, NOT_COMPARABLE, Verdict
from albot1.report.tuning import LEGEND, held_in_share, marked
from albot1.runs.folder import read_run

PAGE = "README.md"
FIGURES = "figures"


def pictured() -> tuple[str, ...]:
    """The datasets whose every-method plots the thesis suite's benchmark report draws (Experiments 3-5).

    The page draws its own figures for the rest, and the public logs' plots are in the default suite's report.
    """
    ds = thesis_datasets()
    return (ds.square, ds.dense, ds.sparse)


def own_records(records: list[CellRecord]) -> list[CellRecord]:
    """The cells of :func:`pictured`: the benchmark report of the thesis suite draws its per-dataset plots for these."""
    shown = pictured()
    return [r for r in records if r.cell.dataset_label in shown]


@dataclass(frozen=True)
class Drawn:
    """A figure file made for a request (or, ``path`` None, why it could not be made)."""

    caption: str
    path: Path | None
    reason: str | None = None
    #: Another report's figure (:meth:`_Figures.linked`): drawn there with its SVG twin, maybe not yet on disk;
    #: without ``path``, that no report draws it (known from the stores: kept like a drawn figure).
    linked: bool = False


class _Figures:
    """Draws the requested figures once each; replays are shared between the trace and the animation."""

    def __init__(self, ev: Evidence, out: Path, colors: dict[str, str]) -> None:
        self.ev = ev
        self.out = out
        self.dir = out / FIGURES
        self.dir.mkdir(parents=True, exist_ok=True)
        self.colors = colors
        self._replays: dict[Path, Replay | ReportError] = {}
        self._drawn_maps: dict[str, set[str]] = {}

    def linked(self, dataset: str) -> Path | None:
        """The maps figure of ``dataset`` that a companion store's report draws (``reports/<store>/plots``).

        Known from the companion store (:func:`~albot1.report.map_plots.maps_drawn`), never by looking for
        the file: this page is the same whether that report is built before, while or after it.
        """
        for store in self.ev.stores[1:]:
            if store.name not in self._drawn_maps:
                self._drawn_maps[store.name] = maps_drawn(store.records)
            if dataset in self._drawn_maps[store.name]:
                return self.out.parent / store.name / "plots" / f"{slug(dataset)}-maps.png"
        return None

    def replay(self, record: CellRecord) -> Replay:
        found = self._replays.get(record.run_dir)
        if found is None:
            try:
                found = replay_run(record.run_dir)
            except ReportError as exc:
                found = exc
            self._replays[record.run_dir] = found
        if isinstance(found, ReportError):
            raise found
        return found

    def draw(self, request: FigureRequest) -> list[Drawn]:
        try:
            drawn: list[Drawn] = getattr(self, f"_{request.kind.replace('-', '_')}")(request)
            return drawn
        except (Albot1Error, OSError, ValueError) as exc:  # one figure's failure never stops the page
            return [Drawn(request.caption, None, f"{type(exc).__name__}: {exc}")]

    def _record(self, dataset: str, method: str, degradation: str = "none") -> CellRecord:
        found = self.ev.find(dataset, method, degradation)
        if found.record is None:
            raise ReportError(found.missing or "no run")
        return found.record

    def _trace(self, request: FigureRequest) -> list[Drawn]:
        out: list[Drawn] = []
        for method in request.methods:
            caption = f"{request.caption}: `{method}` on `{request.dataset}`"
            try:
                replay = self.replay(self._record(request.dataset, method))
            except ReportError as exc:
                out.append(Drawn(caption, None, str(exc)))
                continue
            stem = slug(f"{request.stem}-{method}")
            title = f"{method} on {request.dataset}"
            out.append(Drawn(caption, plot_update_trace(replay, self.dir / f"{stem}.png", title)))
            out.append(
                Drawn(
                    f"which views triggered an update: `{method}` on `{request.dataset}`",
                    plot_trace_strip(replay, self.dir / f"{stem}-strip.png", title),
                )
            )
        return out

    def _animation(self, request: FigureRequest) -> list[Drawn]:
        method = request.methods[0]
        caption = f"{request.caption}: `{method}` on `{request.dataset}` (GIF)"
        try:
            replay = self.replay(self._record(request.dataset, method))
        except ReportError as exc:
            return [Drawn(caption, None, str(exc))]
        path = self.dir / f"{slug(request.stem)}.gif"
        return [Drawn(caption, animate_map(replay, path, f"{method} on {request.dataset}"))]

    def _maps(self, request: FigureRequest) -> list[Drawn]:
        records = []
        for method in request.methods:
            found = self.ev.find(request.dataset, method)
            if found.record is not None:
                records.append(found.record)
        if not records:
            return [Drawn(request.caption, None, "no method has a completed run on this dataset")]
        path = plot_maps(records, request.dataset, self.dir / f"{slug(request.stem)}.png", self.colors)
        return [Drawn(request.caption, path, None if path else "nothing to draw")]

    def _linked_maps(self, request: FigureRequest) -> list[Drawn]:
        """The maps figure of the companion store's report, when that report draws one."""
        figure = self.linked(request.dataset)
        if figure is not None:
            name = figure.parent.parent.name
            return [Drawn(request.caption.replace("default suite", f"`{name}` report"), figure, linked=True)]
        stores = ", ".join(f"`{store.path}`" for store in self.ev.stores[1:])
        reason = (
            f"no completed run of this dataset in {stores}: no report draws its maps"
            if stores
            else "no companion store to draw it from (`albot1 bench default` makes one)"
        )
        return [Drawn(request.caption, None, reason, linked=True)]

    def _gap_maps(self, request: FigureRequest) -> list[Drawn]:
        panels = []
        for degradation in request.degradations:
            for method in request.methods:
                found = self.ev.find(request.dataset, method, degradation)
                if found.record is None:
                    continue
                gap = self.ev.number(found, LOOP_GAP, "", "m").text()
                panels.append((f"{method} [{degradation}]", read_run(found.record.run_dir), gap))
        if not panels:
            return [Drawn(request.caption, None, "no completed run to draw")]
        path = plot_gap_maps(
            panels, self.dir / f"{slug(request.stem)}.png", request.dataset, columns=len(request.methods)
        )
        return [Drawn(request.caption, path)]

    def _places(self, request: FigureRequest) -> list[Drawn]:
        record = self._record(request.dataset, request.methods[0])
        source = record.run_dir / "places.json"
        try:
            network = json.loads(source.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as exc:
            raise ReportError(f"{source}: cannot read the network of places: {exc}") from None
        path = self.dir / f"{slug(request.stem)}.png"
        render_places(network, path, f"{request.methods[0]} on {request.dataset}")
        return [Drawn(request.caption, path)]


def _cached_draw(figures: _Figures, cache: FigureCache, request: FigureRequest) -> list[Drawn]:
    """``figures.draw(request)``, or what it drew last time when nothing it is drawn from has changed.

    A request reads the runs of its own dataset in every store (and, for a
    linked figure, which other report's figure it links): their records, the
    request itself and the colours make its digest
    (:mod:`albot1.report.figure_cache`). Drawings that failed are not kept:
    their reason is worked out again. A linked figure is another report's
    file: it is not one of the group's files (that report may be drawing it).
    """
    records = [r for store in figures.ev.stores for r in store.records if r.cell.dataset_label == request.dataset]
    linked = figures.linked(request.dataset)
    colors = sorted((k, v) for k, v in figures.colors.items() if k in {r.cell.method_label for r in records})
    where = None if linked is None else linked.relative_to(figures.out.parent).as_posix()
    digest = inputs_digest(records, "thesis", repr(request), colors, where)
    group = f"thesis:{request.stem}"
    cached = cache.lookup(group, digest)
    if cached is not None:
        return [
            Drawn(caption, None if path is None else cache.path(path), reason, linked)
            for caption, path, reason, linked in cached.payload
        ]
    drawn = figures.draw(request)
    if all(d.path is not None or d.linked for d in drawn):
        cache.store(
            group,
            digest,
            [d.path for d in drawn if d.path and not d.linked],
            [[d.caption, None if d.path is None else cache.name(d.path), d.reason, d.linked] for d in drawn],
        )
    else:
        # the report is not skipped as a whole until this figure is drawn; what was drawn is linked meanwhile
        cache.unsettled(group, [d.path for d in drawn if d.path and not d.linked])
    return drawn


# --------------------------------------------------------------------------- Markdown


def _verdict_cell(verdict: Verdict) -> str:
    word = marked(f"**{verdict.word}**", verdict.held_in)
    return f"{word}: {verdict.reason}".replace("|", "\\|").replace("\n", " ")


def _claim_cells(row: ClaimRow, columns: dict[str, str]) -> list[str]:
    if "" in row.verdicts:  # one verdict for every variant: a check of the stand-in, not of Albot1
        return [_verdict_cell(row.verdicts[""])] + ["(setup check: same for every variant)"] * (len(columns) - 1)
    return [_verdict_cell(row.verdicts[c]) if c in row.verdicts else "–" for c in columns]


def _tally(verdicts: list[Verdict]) -> str:
    """``**holds**`` for one verdict; ``holds 12, does not hold 3 (of 15)`` for a claim tested on many datasets."""
    if len(verdicts) == 1:
        return marked(f"**{verdicts[0].word}**", verdicts[0].held_in)
    counts: dict[str, int] = {}
    for verdict in verdicts:
        counts[verdict.word] = counts.get(verdict.word, 0) + 1
    parts = [f"{word} {counts[word]}" for word in (HOLDS, FAILS, NOT_COMPARABLE) if word in counts]
    tuned = held_in_share(sum(v.held_in for v in verdicts), len(verdicts))
    return f"{', '.join(parts)} (of {len(verdicts)} datasets{tuned})"


def _summary(sections: list[Section]) -> list[str]:
    """One row per claim of each experiment; a claim tested on several datasets counts its verdicts."""
    lines = [
        "| experiment | claim | thesis | literal reading | thesis preset | Albot1+ |",
        "|---|---|---|---|---|---|",
    ]
    for section in sections:
        for text, rows in section.claim_groups():
            if all("" in row.verdicts for row in rows):
                cells = [_tally([row.verdicts[""] for row in rows])]
                cells += ["(setup check: same for every variant)"] * (len(section.columns) - 1)
            else:
                cells = [_tally([row.verdicts[c] for row in rows if c in row.verdicts]) for c in section.columns]
            lines.append(
                f"| [{section.title.split(':')[0]}](#{section.anchor}) | {text} | {rows[0].thesis} | "
                + " | ".join(cells)
                + " |"
            )
    return lines


def _held_in_lines(sections: list[Section]) -> list[str]:
    """The mark's legend when a verdict rests on a number of a variant on a dataset it was tuned on."""
    verdicts = [v for section in sections for row in section.claims for v in row.verdicts.values()]
    tuned = sum(v.held_in for v in verdicts)
    if not tuned:
        return []
    return [
        f"{LEGEND} A verdict marked so rests on such a number ({tuned} of {len(verdicts)} verdicts): the Albot1 "
        "variants' values were chosen on most of the stand-in worlds and the public logs, so a claim that "
        "holds there shows the method fits them; the generalisation page tests held-out logs.",
        "",
    ]


def _counts(sections: list[Section]) -> str:
    words: dict[str, int] = {}
    for section in sections:
        for row in section.claims:
            for verdict in row.verdicts.values():
                words[verdict.word] = words.get(verdict.word, 0) + 1
    return ", ".join(f"{n} {w}" for w, n in sorted(words.items())) or "no verdict"


def _section_lines(section: Section, drawn: dict[str, list[Drawn]], out: Path) -> list[str]:
    lines = [
        f'<a id="{section.anchor}"></a>',
        f"## {section.title}",
        "",
        f"**Thesis (published, not measured here):** {section.thesis_says}",
        "",
        f"**Stand-in:** {section.stand_in}",
        "",
    ]
    if section.claims:
        heads = [f"{name} (`{label}`)" for label, name in section.columns.items()]
        lines += [
            "| claim | thesis | " + " | ".join(heads) + " |",
            "|---|---|" + "---|" * len(heads),
        ]
        for row in section.claims:
            lines.append(f"| {row.text} | {row.thesis} | " + " | ".join(_claim_cells(row, section.columns)) + " |")
        lines.append("")
    for note in section.notes:
        lines += [f"- {note}"]
    if section.notes:
        lines.append("")
    for table in section.tables:
        lines += [table, ""]
    figures = [d for request in section.figures for d in drawn.get(request.stem, [])]
    if figures:
        lines += ["Figures:", ""]
        for figure in figures:
            if figure.path is None:
                lines.append(f"- {figure.caption}: not drawn ({figure.reason})")
                continue
            link = rel(figure.path, out)
            vector = vector_of(figure.path)
            svg = figure.path.suffix == ".png" and (figure.linked or vector.is_file())
            twin = f" ([SVG]({rel(vector, out)}))" if svg else ""
            lines.append(f"- [{figure.caption}]({link}){twin}")
        lines.append("")
        for figure in figures:
            if figure.path is not None:
                lines += [f"![{figure.caption}]({rel(figure.path, out)})", ""]
    return lines


def _parameters(ev: Evidence, sections: list[Section], out: Path) -> list[str]:
    lines = [
        "## Parameters",
        "",
        "Our readings of the thesis's claims (the thresholds the verdicts use; the thesis gives none, "
        "`albot1/report/thesis/claims.py`):",
        "",
        "| reading | value | meaning | why |",
        "|---|---|---|---|",
    ]
    for name, reading in READINGS.items():
        value = f"{reading.value:g} {reading.unit}".strip()
        lines.append(f"| `{name}` | {value} | {reading.meaning} | {reading.why} |")
    lines += [
        "",
        "- Induced odometry error (Experiment 3): the `thesis` degradation, +0.1 m and +1 deg added to every "
        "step's odometry before any method sees it (docs/metrics.md, README: `--degrade thesis`).",
        "- Metric settings, as stored in the metrics of the runs (docs/metrics.md):",
    ]
    for store in ev.stores:
        shape = next((sb for r in store.records if r.metrics is not None and (sb := r.metrics.get(MAP_SHAPE))), None)
        if shape is not None:
            lines.append(
                f"  - map shape: tolerance {shape.tolerance_m:g} m, voxel {shape.voxel_m:g} m, "
                f"alignment {shape.alignment} (`{store.path}`)"
            )
        o = next((ob for r in store.records if r.metrics is not None and (ob := r.metrics.get(ORIENTATION))), None)
        if o is not None:
            lines.append(
                f"  - orientation: a stop every {o.every_m:g} m, bearing undefined within {o.min_distance_m:g} m of "
                f"the start, alignment {o.alignment} (`{store.path}`)"
            )
    lines += [
        "  - loop gap: start vs end of the route, alignment-free (docs/metrics.md, 'Loop gap')",
        "",
        "Methods (each label's preset and overrides; every config field of every run is in its `result.json`, linked):",
        "",
        "| method | store | preset | overrides | run folder |",
        "|---|---|---|---|---|",
    ]
    wanted = {m for s in sections for r in s.figures for m in r.methods} | {
        label for s in sections for label in s.columns
    }
    seen: set[tuple[str, str]] = set()
    for store in ev.stores:
        for rec in store.records:
            c = rec.cell
            if rec.status != "done" or (c.method_label, store.name) in seen:
                continue
            if c.method_label not in wanted and store.name != THESIS_SUITE:
                continue
            seen.add((c.method_label, store.name))
            overrides = ", ".join(f"{k}={v}" for k, v in c.overrides.items()) or "none"
            lines.append(
                f"| `{c.method_label}` | `{store.path}` | `{c.preset}` | {overrides} | "
                f"[result.json]({rel(rec.run_dir / 'result.json', out)}) |"
            )
    return [*lines, ""]


def write_thesis_page(
    results_dir: Path,
    out: Path,
    *,
    benchmark_index: str = "benchmark.md",
    companions: tuple[str, ...] = COMPANION_SUITES,
    plots: bool = True,
    index_follows: bool = False,
) -> Path:
    """Write ``out/README.md`` for the thesis suite's ``results_dir`` (figures under ``out/figures``).

    ``benchmark_index`` is linked when it exists, or when ``index_follows``: the caller writes it next
    (:func:`albot1.report.index.build_report` writes this page while its figures are drawn, before the index).
    """
    ev = open_stores(results_dir, companions)
    sections = all_sections(ev)
    labels = [r.cell.method_label for s in ev.stores for r in s.records]
    drawn: dict[str, list[Drawn]] = {}
    if plots:
        figures = _Figures(ev, out, method_colors(labels))
        cache = FigureCache(figures.dir)
        for section in sections:
            for request in section.figures:
                drawn[request.stem] = _cached_draw(figures, cache, request)
        cache.save()
    else:
        clear_figures(out / FIGURES)
    lines = [
        "# The thesis's experiments, reproduced",
        "",
        "For each experiment of the thesis (chapters 3.2 and 4.2): what the thesis claims and the numbers it "
        "reports (labelled **thesis**, published, never measured here), our numbers on the data that stands in "
        "for its own, and a verdict computed from the stored numbers for Albot1 in the literal reading of the "
        "thesis (`literal`), the thesis preset (`thesis`) and Albot1+ (`plus`): **holds**, **does not hold** or "
        "**not comparable** (with the reason: a metric that does not apply, a method not installed, a run not "
        "made). How each verdict is computed: docs/thesis-reproduction.md.",
        "",
        "Generated from "
        + ", ".join(
            f"`{s.path}` (suite `{s.plan.suite}`, code `{s.code_version}`, {as_of(s.records)})" for s in ev.stores
        )
        + ".",
        "",
        f"Verdicts: {_counts(sections)}.",
        "",
        *_held_in_lines(sections),
    ]
    if ev.notes:
        lines += ["Notes on the stores:", "", *[f"- {note}" for note in ev.notes], ""]
    if index_follows or (out / benchmark_index).is_file():
        lines += [
            f"This suite's full benchmark report (every table and plot): [{benchmark_index}]({benchmark_index}), "
            "[index.html](index.html).",
            "",
        ]
    lines += ["## Verdicts at a glance", "", *_summary(sections), "", *stand_ins(ev)]
    for section in sections:
        lines += _section_lines(section, drawn, out)
    lines += _parameters(ev, sections, out)
    lines += [
        "## Data",
        "",
        "The sha256 (first 12 hex digits) of the files each dataset's numbers come from:",
        "",
        *[f"- {md_text(line)}" for line in data_lines([r for s in ev.stores for r in s.records])],
    ]
    page = out / PAGE
    page.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return page
