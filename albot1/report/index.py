"""Build ``reports/<suite>/``: tables, plots, the README that links them and ``index.html`` that shows them.

The index states what a reader needs to trust or reproduce the numbers: the
machine, the code and library versions, the seeds and degradations, every
failed cell with its reason and log, every cell the runner never reached,
and the datasets and methods that were skipped with the command that
fetches or installs them. ``README.md`` is that index for a code host;
``index.html`` (:mod:`albot1.report.html`) is the same report on one page
with the tables and every plot, for a browser.
"""

from __future__ import annotations

from contextlib import nullcontext
from pathlib import Path

from albot1.bench.grid import GridPlan
from albot1.report.collect import COST_COLUMNS, METRIC_COLUMNS, CellRecord, as_of, collect
from albot1.report.column_selection import ALL_COLUMNS, ColumnSelection
from albot1.report.external_notes import external_markdown
from albot1.report.figure_cache import clear_figures
from albot1.report.figure_pool import PLOTS_DIR, PlotProgress, start_plots
from albot1.report.folders import default_out
from albot1.report.generalisation import PAGE as GENERALISATION_PAGE
from albot1.report.generalisation import TABLE as GENERALISATION_TABLE
from albot1.report.generalisation import write_generalisation
from albot1.report.html import INDEX_HTML, rel, write_html
from albot1.report.interactive_page import VIEWS_DIR, write_views
from albot1.report.map_plots import MapStyle
from albot1.report.markdown import code, text
from albot1.report.paired_tables import paired_rows
from albot1.report.plots import method_colors, vector_of
from albot1.report.provenance import data_by_dataset, describe_data, rerun_command, separate_data
from albot1.report.standard import PAGE as STANDARD_PAGE
from albot1.report.standard import TABLE as STANDARD_TABLE
from albot1.report.standard import on_standard_logs, write_standard
from albot1.report.standard_paired import PAIRED_TABLE as STANDARD_PAIRED_TABLE
from albot1.report.tables import Aggregates, write_tables
from albot1.report.thesis.experiments.datasets import THESIS_SUITE
from albot1.report.thesis.page import own_records, write_thesis_page
from albot1.versions import commit_label


def _rel(path: Path, start: Path) -> str:
    return rel(path, start)


def _machine_lines(plan: GridPlan) -> list[str]:
    m = plan.machine
    libraries = ", ".join(f"{k} {v}" for k, v in (m.get("libraries") or {}).items() if v)
    return [
        f"- CPUs: {text(m.get('cpu_count'))} logical ({text(m.get('cpu_count_physical'))} physical), "
        f"memory {text(m.get('memory_gb'))} GB; {text(m.get('processor'))}",
        f"- platform: {text(m.get('platform'))}; Python {text(m.get('python'))}",
        f"- code version: {code(m.get('code_version'))} ({commit_label(m.get('git'))})",
        f"- libraries: {text(libraries)}",
    ]


def _status_counts(records: list[CellRecord]) -> dict[str, int]:
    counts: dict[str, int] = {"done": 0, "failed": 0, "not run": 0}
    for rec in records:
        counts[rec.status] = counts.get(rec.status, 0) + 1
    return counts


def _failure_lines(records: list[CellRecord], out: Path) -> list[str]:
    failed = [r for r in records if r.status == "failed"]
    if not failed:
        return ["No cell failed.", ""]
    counts: dict[tuple[str, str], int] = {}
    for rec in failed:
        kind = rec.failure.kind if rec.failure else "?"
        counts[(rec.cell.method_label, kind)] = counts.get((rec.cell.method_label, kind), 0) + 1
    lines = [
        f"{len(failed)} cells failed: " + ", ".join(f"{text(m)} {n} ({text(k)})" for (m, k), n in counts.items()) + ".",
        "",
        "| dataset | method | degradation | seed | kind | reason | log |",
        "|---|---|---|---|---|---|---|",
    ]
    for rec in failed:
        c, f = rec.cell, rec.failure
        assert f is not None
        log = f"[log]({_rel(rec.run_dir / f.log, out)})" if f.log else "–"
        lines.append(
            f"| {text(c.dataset_label)} | {text(c.method_label)} | {text(c.degradation)} | {c.seed} | {text(f.kind)} "
            f"| {text(f.reason)} | {log} |"
        )
    return [*lines, ""]


def write_index(
    plan: GridPlan,
    records: list[CellRecord],
    tables: dict[str, Path],
    plots: dict[str, list[Path]],
    out: Path,
    results_dir: Path,
    name: str = "README.md",
) -> Path:
    counts = _status_counts(records)
    lines: list[str] = [
        f"# Benchmark report: suite {code(plan.suite)}",
        "",
        text(plan.description.strip()) if plan.description.strip() else "",
        "",
        f"Generated from {code(results_dir)} ({as_of(records)}; suite file {code(plan.suite_path)}).",
        "",
        f"Cells: {len(records)} planned, {counts['done']} complete, {counts['failed']} failed, "
        f"{counts['not run']} not run.",
        "",
        "## Machine and versions",
        "",
        *_machine_lines(plan),
        "",
        "## Grid",
        "",
        f"- seeds: {', '.join(map(str, plan.seeds))} (the deterministic degradations `none`, `thesis`, "
        "`bias:...` and `offset:...` run with the first seed only: every seed would repeat the same run)",
        f"- degradations: {', '.join(code(d) for d in plan.degradations)} "
        "(`none` = the dataset's own odometry; swept ones only on datasets with reference poses)",
        f"- datasets: {', '.join(text(d) for d in dict.fromkeys(r.cell.dataset_label for r in records)) or '(none)'}",
        f"- methods: {', '.join(text(m) for m in dict.fromkeys(r.cell.method_label for r in records)) or '(none)'}",
        "",
        "## Data",
        "",
        "The checksums (sha256, first 12 hex digits) of the files each dataset's numbers come from "
        "(`result.json`, `dataset_info.data_sha256`):",
        "",
        *[f"- {text(d)}: {text(describe_data(files))}" for d, files in data_by_dataset(records).items()],
        "",
        f"**[The whole report on one page: {INDEX_HTML}]({INDEX_HTML})** (tables, every plot and an interactive "
        "view per dataset: zoom, pan, the error of each pose on hover; open it in a browser, it needs no network).",
        "",
        "## Tables",
        "",
        f"- [accuracy (Markdown)]({_rel(tables['metrics.md'], out)}) · [CSV]({_rel(tables['metrics.csv'], out)}) · "
        f"[LaTeX]({_rel(tables['metrics.tex'], out)})",
        f"- [cost (Markdown)]({_rel(tables['cost.md'], out)}) · [CSV]({_rel(tables['cost.csv'], out)}) · "
        f"[LaTeX]({_rel(tables['cost.tex'], out)})",
        f"- [every cell, accuracy and status (CSV)]({_rel(tables['cells.csv'], out)}) · "
        f"[every cell, cost (CSV)]({_rel(tables['cells-cost.csv'], out)})",
        *(
            [
                f"- [the standard benchmark: relation metric on the five Freiburg logs, published figures beside "
                f"ours]({_rel(tables[STANDARD_PAGE], out)}) · [CSV]({_rel(tables[STANDARD_TABLE], out)})"
            ]
            if STANDARD_PAGE in tables
            else []
        ),
        *(
            [
                f"- [every method against the odometry it was given (paired comparison, held-in marks)]"
                f"({_rel(tables[GENERALISATION_PAGE], out)}) · [CSV]({_rel(tables[GENERALISATION_TABLE], out)})"
            ]
            if GENERALISATION_PAGE in tables
            else []
        ),
        "",
        "Cost numbers were measured with the suite's parallelism on a possibly shared machine; "
        "compare them within one report.",
        "",
    ]
    if plots:
        lines += ["## Plots", ""]
        for plot in plots.get("", []):
            lines += [f"![runtime]({_rel(plot, out)})", ""]
        for dataset, files in plots.items():
            if not dataset or not files:
                continue
            lines += [
                f"### {text(dataset)}",
                "",
                *[f"- [{f.stem}]({_rel(f, out)}) ([SVG]({_rel(vector_of(f), out)}))" for f in files],
                "",
            ]
    lines += external_markdown(records)
    lines += ["## Failed cells", "", *_failure_lines(records, out)]
    not_run = [r for r in records if r.status == "not run"]
    if not_run:
        lines += [
            "## Cells not run",
            "",
            "The runner stopped before these cells finished; run "
            f"{code(rerun_command(plan, results_dir))} again to complete them.",
            "",
            *[f"- {text(r.cell.describe())}" for r in not_run],
            "",
        ]
    lines += ["## Skipped datasets", ""]
    if plan.skipped_datasets:
        lines += [
            f"- {code(s.name)}: {text(s.reason)}" + (f" — fetch it with {code(s.hint)}" if s.hint else "")
            for s in plan.skipped_datasets
        ]
    else:
        lines.append("None: every dataset the suite selects was available.")
    lines += ["", "## Skipped methods", ""]
    if plan.skipped_methods:
        lines += [
            f"- {code(s.name)}: {text(s.reason)}" + (f" ({code(s.hint)})" if s.hint else "")
            for s in plan.skipped_methods
        ]
    else:
        lines.append("None.")
    lines.append("")
    index = out / name
    index.write_text("\n".join(lines), encoding="utf-8")
    return index


def _remove_unwritten(out: Path, *names: str) -> None:
    """Delete the report's own ``names`` in ``out`` that this build does not write.

    An earlier report into the same folder (of this store before cells were removed, or of another store)
    may have written them: left there, they would show its numbers beside this report's, unlinked but there
    to be copied; a report built afresh has none.
    """
    for name in names:
        (out / name).unlink(missing_ok=True)


def build_report(
    results_dir: str | Path,
    out: str | Path | None = None,
    *,
    plots: bool = True,
    map_style: MapStyle = "grid",
    jobs: int = 1,
    progress: PlotProgress | None = None,
    columns: ColumnSelection = ALL_COLUMNS,
) -> Path:
    """Tables, plots, README.md and index.html for ``results_dir``; returns the README path.

    ``jobs``: worker processes drawing the plots (:mod:`albot1.report.figure_pool`, which tells ``progress``).
    ``columns``: the number columns of the metrics and cost tables (:mod:`albot1.report.column_selection`).

    For the ``thesis`` suite README.md is the thesis reproduction page
    (:mod:`albot1.report.thesis.page`) and the benchmark index is ``benchmark.md``.
    """
    results = Path(results_dir)
    target = Path(out) if out is not None else default_out(results)
    plan, collected = collect(results)
    records = separate_data(collected)  # runs of one dataset on different data never share a row
    target.mkdir(parents=True, exist_ok=True)
    colors = method_colors(r.cell.method_label for r in records)
    thesis = plan.suite == THESIS_SUITE
    pictured = own_records(records) if thesis else records  # the thesis suite's public-log runs: see reports/default
    tabled = Aggregates(records)  # computed once, read by the tables, the figures and index.html
    drawn_from = tabled if pictured is records else Aggregates(pictured)  # a subset: tables of its own
    # the figures first: worker processes draw them while this one writes the tables and pages (figure_pool)
    plotting = (
        start_plots(pictured, target, colors, map_style=map_style, jobs=jobs, progress=progress, aggregates=drawn_from)
        if plots
        else nullcontext(None)
    )
    if not plots:  # an earlier build's figures would stay beside this build's tables
        for folder in (PLOTS_DIR, VIEWS_DIR):
            clear_figures(target / folder)
    with plotting as pending:
        paired = paired_rows(records)  # the accuracy tables' paired comparisons (metrics.md, paired.csv, index.html)
        tables = write_tables(records, target, paired, columns, tabled)
        if on_standard_logs(plan, records):  # a page of five "not measured" logs says nothing (a user's own bags)
            tables[STANDARD_PAGE], tables[STANDARD_TABLE] = write_standard(plan, records, target, results)
        else:
            _remove_unwritten(target, STANDARD_PAGE, STANDARD_TABLE, STANDARD_PAIRED_TABLE)
        generalisation = write_generalisation(plan, records, target, results)
        if generalisation is not None:
            tables[GENERALISATION_PAGE], tables[GENERALISATION_TABLE] = generalisation
        else:
            _remove_unwritten(target, GENERALISATION_PAGE, GENERALISATION_TABLE)
        views = write_views(pictured, target, colors) if plots else None
        name = "benchmark.md" if thesis else "README.md"
        page = (
            write_thesis_page(results, target, benchmark_index=name, plots=plots, index_follows=True)
            if thesis
            else None
        )
        made = pending.result() if pending is not None else {}
    index = write_index(plan, records, tables, made, target, results, name)
    write_html(
        plan,
        records,
        tabled.metrics,
        tabled.cost,
        (METRIC_COLUMNS, COST_COLUMNS),
        {**tables, index.name: index},
        made,
        colors,
        target,
        results,
        extra_links=[("the thesis's experiments, reproduced (README.md)", page)] if page is not None else None,
        paired=paired,
        views=views,
        selection=columns,
    )
    return page if page is not None else index
