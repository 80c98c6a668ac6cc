"""``index.html``: the whole report on one self-contained page.

Self-contained means it opens from the report folder with no network: the
style and the table-sorting script are inline, every link and image is a
relative path into the report folder (the plots, the CSV/Markdown/LaTeX
tables, the failed cells' logs in the results folder), and nothing is
fetched from elsewhere. ``tests/unit/report/test_report_html.py`` checks
that every link and image resolves; a browser test opens it headless.

Each dataset has an interactive view (:mod:`albot1.report.interactive`):
its trajectories and maps over the reference, zoom and pan, the stored
per-pose error on hover, drawn by plotly from ``interactive/`` in the report
folder (plotly's bundle included, so still no network).

Tables are sortable: a click on a column header sorts its rows (numbers by
value, ``n/a``/``failed`` last), another click reverses the order. Each
results table has a "Columns" menu above it: a checkbox per number column
hides or shows that column, header and every cell, in the browser (nothing
is stored; a reload shows every column again). ``albot1 report --columns``
chooses the columns before that (:mod:`albot1.report.column_selection`).
"""

from __future__ import annotations

import html
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from albot1.bench.grid import GridPlan
from albot1.report.collect import CellRecord, Column, as_of
from albot1.report.column_selection import ALL_COLUMNS, ColumnSelection
from albot1.report.external_notes import external_html
from albot1.report.interactive_page import VIEWS_DIR, View, view_html, views_scripts
from albot1.report.number_text import EXAMPLE, SEEDS_LEGEND
from albot1.report.paired_tables import PairedRow, html_table
from albot1.report.plots import vector_of
from albot1.report.provenance import data_by_dataset, describe_data, rerun_command
from albot1.report.tables import cell_text, columns_present, na_notes, na_outline
from albot1.report.tuning import LEGEND, marked
from albot1.versions import commit_label

if TYPE_CHECKING:
    import pandas as pd

INDEX_HTML = "index.html"

STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; margin: 1.5em auto; max-width: 1400px;
       padding: 0 1em; color: #1a1a1a; line-height: 1.4; }
h1 { font-size: 1.6em; } h2 { margin-top: 1.8em; border-bottom: 1px solid #ccc; } h3 { margin-top: 1.4em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.85em; }
th, td { border: 1px solid #d0d0d0; padding: 3px 7px; }
th { background: #f0f0f0; cursor: pointer; user-select: none; position: sticky; top: 0; }
th.sorted-asc::after { content: " \\25B2"; } th.sorted-desc::after { content: " \\25BC"; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.na { color: #888; text-align: center; } td.failed { color: #b00020; font-weight: 600; text-align: center; }
tr.failed-row td { background: #fff3f3; }
.swatch { display: inline-block; width: 0.9em; height: 0.9em; border-radius: 2px; vertical-align: middle;
          margin-right: 0.3em; border: 1px solid #555; }
figure { margin: 0.8em 0 1.6em 0; } figure img { max-width: 100%; height: auto; border: 1px solid #e0e0e0; }
figcaption { font-size: 0.85em; color: #444; }
.notes { font-size: 0.85em; color: #444; } .meta { font-size: 0.9em; }
nav a { margin-right: 0.8em; }
.scroll { overflow-x: auto; max-width: 100%; } td.label { white-space: nowrap; }
details.colpick { font-size: 0.85em; margin: 0.4em 0 0 0; } details.colpick summary { cursor: pointer; color: #333; }
details.colpick label { display: inline-block; margin: 0.15em 0.9em 0.15em 0; white-space: nowrap; }
th[hidden], td[hidden] { display: none; }
"""

#: Click-to-sort for every table of class "sortable" (numbers by data-v, text otherwise; n/a and failed last).
SCRIPT = """
document.querySelectorAll("table.sortable").forEach(function (table) {
  table.querySelectorAll("th").forEach(function (th, col) {
    th.addEventListener("click", function () {
      var body = table.tBodies[0], rows = Array.prototype.slice.call(body.rows);
      var asc = !th.classList.contains("sorted-asc");
      table.querySelectorAll("th").forEach(function (h) { h.classList.remove("sorted-asc", "sorted-desc"); });
      th.classList.add(asc ? "sorted-asc" : "sorted-desc");
      rows.sort(function (a, b) {
        var x = a.cells[col], y = b.cells[col];
        var vx = x.dataset.v, vy = y.dataset.v;
        if (vx === undefined && vy === undefined) {
          return (asc ? 1 : -1) * x.textContent.localeCompare(y.textContent);
        }
        if (vx === undefined) { return 1; }
        if (vy === undefined) { return -1; }
        return (asc ? 1 : -1) * (parseFloat(vx) - parseFloat(vy));
      });
      rows.forEach(function (r) { body.appendChild(r); });
    });
  });
});
document.querySelectorAll("details.colpick").forEach(function (pick) {
  var table = pick.parentNode.querySelector("table"), boxes = pick.querySelectorAll("input[data-col]");
  function show(box) {
    var col = parseInt(box.dataset.col, 10);
    Array.prototype.forEach.call(table.rows, function (row) { row.cells[col].hidden = !box.checked; });
  }
  boxes.forEach(function (box) { box.addEventListener("change", function () { show(box); }); });
  pick.querySelector("button").addEventListener("click", function () {
    boxes.forEach(function (box) { box.checked = true; show(box); });
  });
});
"""

#: What a robustness figure's x axis holds (a suite may sweep a wrong laser offset and scan dropout too).
_PER_LEVEL = "per degradation (of the odometry, or a wrong laser offset or scan dropout): mean over seeds"
#: Captions of the per-dataset figures, by the suffix of their file names.
CAPTIONS = {
    "trajectories": "Trajectories over the reference (rigid alignment, as for the ATE).",
    "ape": "Absolute position error per pose, per method (colour bar in m; dashed: reference).",
    "error-distance": "Position error along the route, against distance travelled on the reference.",
    "rpe-boxes": "Relative error per segment length (boxes: quartiles; whiskers: 1.5 IQR; outliers not drawn).",
    "maps": "Maps in the reference's frame, one panel per method, with the reference and each trajectory.",
    "robustness-ate": f"ATE RMSE {_PER_LEVEL}, ± std, min and max.",
    "robustness-drift": f"RPE per 10 m {_PER_LEVEL}, ± std, min and max.",
    "robustness-loop-gap": f"Loop gap {_PER_LEVEL}, ± std, min and max.",
    "scan-time": "Per-scan processing time along the sequence (running median).",
    "runtime": "Median per-scan time per dataset and method on the dataset's own odometry (whisker: p95).",
}


def _e(text: object) -> str:
    return html.escape(str(text), quote=True)


def rel(path: Path, start: Path) -> str:
    """``path`` relative to the folder ``start``, with forward slashes (a link that works from the page)."""
    return Path(os.path.relpath(path.resolve(), start.resolve())).as_posix()


def _number_cell(row: pd.Series, column: str) -> str:
    text = cell_text(row, column)
    mean = row[f"{column}_mean"]
    if isinstance(mean, float) and math.isnan(mean):
        css = "failed" if text == "failed" else "na"
        title = row.get(f"{column}_na")
        tip = f' title="{_e(title)}"' if isinstance(title, str) else ""
        return f'<td class="{css}"{tip}>{_e(text)}</td>'
    return f'<td class="num" data-v="{float(mean):.12g}">{_e(text)}</td>'


#: The columns before the number columns (method, degradation, seeds): always shown, so never in the menu.
IDENTITY = ("method", "degradation", "seeds")


def column_menu(columns: dict[str, Column], present: list[str]) -> str:
    """The "Columns" menu of one table: a checkbox per number column (its cells are at IDENTITY + i)."""
    boxes = "".join(
        f'<label title="{_e(key)}"><input type="checkbox" data-col="{len(IDENTITY) + i}" checked> '
        f"{_e(columns[key].header)}</label>"
        for i, key in enumerate(present)
    )
    return (
        '<details class="colpick"><summary>Columns: hide or show</summary>'
        f'{boxes}<button type="button">show all</button></details>'
    )


def table_html(group: pd.DataFrame, columns: dict[str, Column], colors: dict[str, str]) -> str:
    """One dataset's aggregated rows as a sortable HTML table with its column menu and not-applicable notes.

    ``columns``: the number columns to show (a selection's pick); those that apply to no row are left out.
    """
    present, absent = columns_present(group, columns)
    head = [*IDENTITY, *[columns[c].header for c in present], "status"]
    lines = [
        '<div class="table-box">',
        *([column_menu(columns, present)] if present else []),
        '<div class="scroll"><table class="sortable">',
        "<thead><tr>" + "".join(f"<th>{_e(h)}</th>" for h in head) + "</tr></thead>",
    ]
    lines.append("<tbody>")
    for _, row in group.iterrows():
        css = ' class="failed-row"' if row["status"] != "ok" else ""
        swatch = f'<span class="swatch" style="background:{colors.get(str(row["method"]), "#999")}"></span>'
        tuned = bool(row.get("held_in", False))
        tip = f' title="{_e(LEGEND)}"' if tuned else ""
        cells = [
            f'<td class="label"{tip}>{swatch}{_e(marked(str(row["method"]), tuned))}</td>',
            f'<td class="label">{_e(row["degradation"])}</td>',
            f'<td class="num" data-v="{int(row["seeds"])}">{int(row["seeds"])}</td>',
            *[_number_cell(row, c) for c in present],
            f"<td>{_e(row['status'])}</td>",
        ]
        lines.append(f"<tr{css}>" + "".join(cells) + "</tr>")
    lines.append("</tbody></table></div></div>")
    notes = na_notes(group, columns, present, absent)
    if notes:
        items = [
            f"<li>{_e(item)}"
            + ("<ul>" + "".join(f"<li>{_e(sub)}</li>" for sub in subs) + "</ul>" if subs else "")
            + "</li>"
            for item, subs in na_outline(notes)
        ]
        lines.append('<ul class="notes">' + "".join(items) + "</ul>")
    return "\n".join(lines)


def _figure(png: Path, out: Path) -> str:
    kind = next((k for k in sorted(CAPTIONS, key=len, reverse=True) if png.stem.endswith(k)), "")
    vector = vector_of(png)
    link = f' (<a href="{_e(rel(vector, out))}">SVG</a>)' if vector.is_file() else ""
    return (
        f'<figure><a href="{_e(rel(png, out))}"><img src="{_e(rel(png, out))}" alt="{_e(png.stem)}" '
        f'loading="lazy"></a><figcaption>{_e(CAPTIONS.get(kind, png.stem))}{link}</figcaption></figure>'
    )


def write_html(
    plan: GridPlan,
    records: list[CellRecord],
    metrics: pd.DataFrame,
    cost: pd.DataFrame,
    columns: tuple[dict[str, Column], dict[str, Column]],
    tables: dict[str, Path],
    plots: dict[str, list[Path]],
    colors: dict[str, str],
    out: Path,
    results_dir: Path,
    extra_links: list[tuple[str, Path]] | None = None,
    paired: list[PairedRow] | None = None,
    views: tuple[Path | None, dict[str, View]] | None = None,
    selection: ColumnSelection = ALL_COLUMNS,
) -> Path:
    """Write ``out/index.html`` (see module doc); returns its path.

    ``paired``: the accuracy tables' comparisons. ``views``: plotly's bundle and each dataset's interactive view
    (:func:`albot1.report.interactive_page.write_views`), shown after the dataset's tables. ``selection``: the
    number columns the tables show (``columns`` are every column; the selection is stated once above them).
    """
    bundle, dataset_views = views if views is not None else (None, {})
    every_metric, every_cost = columns
    metric_columns, cost_columns = selection.pick(every_metric), selection.pick(every_cost)
    selected = [
        selection.note(every_metric, "metrics.csv", "cells.csv"),
        selection.note(every_cost, "cost.csv", "cells-cost.csv"),
    ]
    counts: dict[str, int] = {"done": 0, "failed": 0, "not run": 0}
    for rec in records:
        counts[rec.status] = counts.get(rec.status, 0) + 1
    datasets = list(dict.fromkeys(r.cell.dataset_label for r in records))
    m = plan.machine
    libraries = ", ".join(f"{k} {v}" for k, v in (m.get("libraries") or {}).items() if v)
    parts: list[str] = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>Benchmark report: {_e(plan.suite)}</title>",
        f"<style>{STYLE}</style></head><body>",
        f"<h1>Benchmark report: suite <code>{_e(plan.suite)}</code></h1>",
        f"<p>{_e(plan.description.strip())}</p>" if plan.description.strip() else "",
        f'<p class="meta">Generated from <code>{_e(results_dir)}</code> ({_e(as_of(records))}; '
        f"suite file <code>{_e(plan.suite_path)}</code>). "
        f"Cells: {len(records)} planned, {counts['done']} complete, {counts['failed']} failed, "
        f"{counts['not run']} not run.</p>",
        "<nav>"
        + "".join(f'<a href="#{_e(a)}">{_e(t)}</a>' for a, t in (("grid", "Grid"), ("tables", "Tables")))
        + "".join(f'<a href="#ds-{i}">{_e(d)}</a>' for i, d in enumerate(datasets))
        + '<a href="#failures">Failures</a><a href="#skipped">Skipped</a></nav>',
        '<h2 id="grid">Grid, machine and versions</h2>',
        "<ul>",
        f"<li>seeds: {_e(', '.join(map(str, plan.seeds)))}; deterministic degradations (none, thesis, bias) run "
        "with the first seed only</li>",
        f"<li>degradations: {_e(', '.join(plan.degradations))} (<code>none</code> = the dataset's own odometry; "
        "swept ones only on datasets with reference poses)</li>",
        f"<li>datasets: {_e(', '.join(datasets) or '(none)')}</li>",
        "<li>methods: "
        + ", ".join(f'<span class="swatch" style="background:{c}"></span>{_e(m_)}' for m_, c in colors.items())
        + "</li>",
        f"<li>machine: {_e(m.get('cpu_count'))} logical CPUs ({_e(m.get('cpu_count_physical'))} physical), "
        f"{_e(m.get('memory_gb'))} GB; {_e(m.get('processor'))}; {_e(m.get('platform'))}; "
        f"Python {_e(m.get('python'))}</li>",
        f"<li>code version <code>{_e(m.get('code_version'))}</code> (<code>{_e(commit_label(m.get('git')))}</code>); "
        f"libraries: {_e(libraries)}</li>",
        "</ul>",
        '<h2 id="tables">Tables</h2>',
        f"<p>Each number: {_e(SEEDS_LEGEND)}, e.g. <code>{_e(EXAMPLE)}</code> for seeds of 1, 2 and 10. "
        "Files: "
        + ", ".join(f'<a href="{_e(rel(p, out))}">{_e(name)}</a>' for name, p in tables.items())
        + ". Cost was measured with the suite's parallelism on a possibly shared machine: compare it within "
        "one report. The menu above each table hides or shows its columns.</p>",
        *[f'<p class="notes">{title}: {_e(note)}</p>' for title, note in zip(("Accuracy", "Cost"), selected) if note],
    ]
    if extra_links:
        parts.append("<ul>" + "".join(f'<li><a href="{_e(rel(p, out))}">{_e(t)}</a></li>' for t, p in extra_links))
        parts.append("</ul>")
    if plots.get(""):
        parts.append("<h3>Runtime across datasets</h3>")
        parts += [_figure(plot, out) for plot in plots[""]]
    data = data_by_dataset(records)
    for i, dataset in enumerate(datasets):
        parts.append(f'<h2 id="ds-{i}">{_e(dataset)}</h2>')
        files = data.get(dataset)
        shown = describe_data(files) if files is not None else "no completed run"
        parts.append(f'<p class="meta">data: {_e(shown)}</p>')
        for title, table, cols in (("Accuracy", metrics, metric_columns), ("Cost", cost, cost_columns)):
            group = table[table["dataset"] == dataset] if not table.empty else table
            if group.empty:
                continue
            parts += [f"<h3>{title}</h3>", table_html(group, cols, colors)]
            if title == "Accuracy":
                parts.append(html_table(paired or [], dataset))
        if dataset in dataset_views:
            parts.append(view_html(dataset_views[dataset]))
        figures = plots.get(dataset, [])
        if figures:
            parts.append("<h3>Plots</h3>")
            parts += [_figure(p, out) for p in figures]
    parts += [external_html(records), '<h2 id="failures">Failed cells</h2>', _failures(records, out)]
    not_run = [r for r in records if r.status == "not run"]
    if not_run:
        parts += [
            "<h2>Cells not run</h2><p>The runner stopped before these cells finished; run "
            f"<code>{_e(rerun_command(plan, results_dir))}</code> again to complete "
            "them.</p><ul>",
            *[f"<li>{_e(r.cell.describe())}</li>" for r in not_run],
            "</ul>",
        ]
    parts += ['<h2 id="skipped">Skipped datasets and methods</h2>', _skipped(plan)]
    parts += [f"<script>{SCRIPT}</script>", *views_scripts(bundle, dataset_views, VIEWS_DIR), "</body></html>", ""]
    page = out / INDEX_HTML
    page.write_text("\n".join(p for p in parts if p), encoding="utf-8")
    return page


def _failures(records: list[CellRecord], out: Path) -> str:
    failed = [r for r in records if r.status == "failed"]
    if not failed:
        return "<p>No cell failed.</p>"
    rows = []
    for rec in failed:
        c, f = rec.cell, rec.failure
        assert f is not None
        log_path = rec.run_dir / f.log if f.log else None
        log = f'<a href="{_e(rel(log_path, out))}">log</a>' if log_path is not None and log_path.is_file() else "–"
        rows.append(
            f"<tr><td>{_e(c.dataset_label)}</td><td>{_e(c.method_label)}</td><td>{_e(c.degradation)}</td>"
            f"<td>{c.seed}</td><td>{_e(f.kind)}</td><td>{_e(f.reason)}</td><td>{log}</td></tr>"
        )
    head = "".join(f"<th>{h}</th>" for h in ("dataset", "method", "degradation", "seed", "kind", "reason", "log"))
    return f'<table class="sortable"><thead><tr>{head}</tr></thead><tbody>{"".join(rows)}</tbody></table>'


def _skipped(plan: GridPlan) -> str:
    items: list[Any] = []
    for s in plan.skipped_datasets:
        hint = f" — fetch it with <code>{_e(s.hint)}</code>" if s.hint else ""
        items.append(f"<li>dataset <code>{_e(s.name)}</code>: {_e(s.reason)}{hint}</li>")
    for s in plan.skipped_methods:
        hint = f" (<code>{_e(s.hint)}</code>)" if s.hint else ""
        items.append(f"<li>method <code>{_e(s.name)}</code>: {_e(s.reason)}{hint}</li>")
    return "<ul>" + "".join(items) + "</ul>" if items else "<p>None: every dataset and method was available.</p>"
