"""The report's column selection (``--columns``), the HTML tables' column menu and the quick report's n/a notes.

The results folder is built by hand (dead reckoning on a 60-pose loop with
reference poses, and the same loop without them, as a user's own bag is) so
no bench run is needed; the reports are built without plots. The browser
test runs Debian's ``chromium`` headless on a copy of ``index.html`` that
ends with a probe script (it clicks a column's checkbox and writes what the
page then shows into the DOM, which ``--dump-dom`` prints), and is skipped
with the reason when chromium is absent.
"""

from __future__ import annotations

import html
import json
import re
import subprocess
from pathlib import Path

import headless_chromium
import pytest
from loop_sequence import loop

from albot1.bench.grid import Cell, GridPlan
from albot1.bench.store import ResultsStore
from albot1.errors import Albot1Error
from albot1.report.collect import COST_COLUMNS, METRIC_COLUMNS
from albot1.report.column_selection import ALL_COLUMNS, ColumnSelection, parse_columns
from albot1.report.html import INDEX_HTML
from albot1.report.index import build_report
from albot1.report.standard import PAGE as STANDARD_PAGE
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

KNOWN = {**METRIC_COLUMNS, **COST_COLUMNS}
SELECTION = ColumnSelection(("loop_gap_m", "ate_rmse_m", "per_scan_ms_median"))
NO_REFERENCE = "the dataset has no reference poses"


def _cell(dataset: str, key: str, degradation: str, seed: int) -> Cell:
    return Cell("quick", dataset, dataset, "odometry", "odometry", "default", degradation, seed, key, "v", 60.0, 99.0)


@pytest.fixture(scope="module")
def results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``loop`` (reference poses): odometry undegraded and over two noisy seeds; ``bare`` (none): undegraded."""
    root = tmp_path_factory.mktemp("results") / "quick"
    store = ResultsStore(root)
    store.runs.mkdir(parents=True)
    cells = []
    for dataset, reference, degradation, seed in (
        ("loop", True, "none", 0),
        ("loop", True, "gauss:0.05:1", 0),
        ("loop", True, "gauss:0.05:1", 1),
        ("bare", False, "none", 0),
    ):
        result = run_method("odometry", loop(dataset, reference), degradation=degradation, seed=seed)
        run_dir = write_run(result, store.runs)
        evaluate_run(run_dir)
        cells.append(_cell(dataset, run_dir.name, degradation, seed))
    store.write_plan(GridPlan("quick", None, "", cells, [], [], {}, [0, 1], ["none", "gauss:0.05:1"], {}))
    return root


@pytest.fixture(scope="module")
def selected(results: Path) -> Path:
    """The report of ``results`` with :data:`SELECTION`."""
    return build_report(results, results.parent / "selected", plots=False, columns=SELECTION).parent


@pytest.fixture(scope="module")
def whole(results: Path) -> Path:
    """The report of ``results`` with every column."""
    return build_report(results, results.parent / "whole", plots=False).parent


def test_a_selection_keeps_its_order_once_each_and_picks_per_table() -> None:
    picked = parse_columns(" loop_gap_m, ate_rmse_m ,per_scan_ms_median,loop_gap_m", KNOWN)
    assert picked == SELECTION and picked.option() == "--columns loop_gap_m,ate_rmse_m,per_scan_ms_median"
    assert list(picked.pick(METRIC_COLUMNS)) == ["loop_gap_m", "ate_rmse_m"]
    assert list(picked.pick(COST_COLUMNS)) == ["per_scan_ms_median"]
    assert ColumnSelection(("ate_rmse_m",)).pick(COST_COLUMNS) == {}
    assert ALL_COLUMNS.pick(METRIC_COLUMNS) == METRIC_COLUMNS and ALL_COLUMNS.note(METRIC_COLUMNS, "m", "c") is None
    assert not set(METRIC_COLUMNS) & set(COST_COLUMNS)  # one key names one column of one table


@pytest.mark.parametrize(
    ("typed", "hint"),
    [
        ("ate_rmse", " (did you mean 'ate_rmse_m'?)"),
        ("Per-Scan-MS-Median", " (did you mean 'per_scan_ms_median' or 'per_scan_ms_mean' or 'per_scan_ms_p95'?)"),
        ("ATE RMSE (m)", " (that is the header of 'ate_rmse_m': name a column by its key)"),
        ("zzz", ""),
    ],
)
def test_an_unknown_key_names_the_closest_and_every_valid_key(typed: str, hint: str) -> None:
    with pytest.raises(Albot1Error) as raised:
        parse_columns(f"relation_m,{typed}", KNOWN)
    assert str(raised.value) == f"--columns: unknown column key {typed!r}{hint}; valid keys: {', '.join(KNOWN)}"


@pytest.mark.parametrize("typed", ["", " ", "ate_rmse_m,,relation_m", "ate_rmse_m,"])
def test_an_empty_key_is_an_error(typed: str) -> None:
    with pytest.raises(Albot1Error, match="expected column keys separated by commas, found an empty one; valid keys"):
        parse_columns(typed, KNOWN)


@pytest.mark.slow
def test_markdown_and_latex_show_the_identity_columns_then_the_selection_in_its_order(selected: Path) -> None:
    text = (selected / "metrics.md").read_text(encoding="utf-8")
    assert (
        # the keys' underscores backslash-escaped: Markdown shows them literally (albot1.report.markdown.text)
        "Columns shown (--columns loop\\_gap\\_m,ate\\_rmse\\_m,per\\_scan\\_ms\\_median): loop gap (m); ATE RMSE (m). "
        f"Hidden here and in metrics.csv: {len(METRIC_COLUMNS) - 2} of the {len(METRIC_COLUMNS)} number columns; "
        "cells.csv has every column of every cell, and a report without --columns shows them all."
    ) in text
    loop = text.split("## loop")[1].split("## bare")[0]
    assert "| method | degradation | seeds | loop gap (m) | ATE RMSE (m) | status |" in loop
    assert "|---|---|---|---:|---:|---|" in loop
    assert [line for line in loop.splitlines() if line.startswith("- ")] == []  # both columns have numbers
    bare = text.split("## bare")[1]
    assert "| method | degradation | seeds | status |\n|---|---|---|---|\n| odometry | none | 1 | ok |" in bare
    assert [line for line in bare.splitlines() if line.strip().startswith("- ")] == [
        "- left out, n/a in every run of this dataset:",
        f"  - loop gap (m) — {NO_REFERENCE}, and the route is not known to be closed",
        f"  - ATE RMSE (m) — {NO_REFERENCE}",
    ]
    cost = (selected / "cost.md").read_text(encoding="utf-8")
    assert "| method | degradation | seeds | per-scan median (ms) | status |" in cost
    assert "Hidden here and in cost.csv: 6 of the 7 number columns; cells-cost.csv has every column" in cost
    tex = (selected / "metrics.tex").read_text(encoding="utf-8")
    assert "% Columns shown (--columns loop_gap_m,ate_rmse_m,per_scan_ms_median)" in tex
    assert "method & degradation & loop gap (m) & ATE RMSE (m) & status \\\\" in tex


@pytest.mark.slow
def test_the_tables_csv_follow_the_selection_and_the_per_cell_csv_keep_every_column(
    selected: Path, whole: Path
) -> None:
    import pandas as pd  # here, not at collection: pandas costs every test run's collection

    identity = ["dataset", "method", "degradation", "seeds", "planned", "failed", "not_run", "status", "held_in"]
    stats = ("mean", "std", "median", "min", "max", "na")
    metrics = pd.read_csv(selected / "metrics.csv")
    assert list(metrics.columns) == identity + [f"{c}_{s}" for c in ("loop_gap_m", "ate_rmse_m") for s in stats]
    cost = pd.read_csv(selected / "cost.csv")
    assert list(cost.columns) == identity + [f"per_scan_ms_median_{s}" for s in stats]
    for name in ("cells.csv", "cells-cost.csv"):
        assert (selected / name).read_bytes() == (whole / name).read_bytes(), name
    everything = pd.read_csv(whole / "metrics.csv")
    assert metrics.equals(everything[metrics.columns])  # the same numbers, fewer columns


def _th_texts(table: str) -> list[str]:
    return [html.unescape(t) for t in re.findall(r"<th>(.*?)</th>", table)]


@pytest.mark.slow
def test_html_tables_show_the_selection_with_a_checkbox_per_number_column(selected: Path, whole: Path) -> None:
    page = (selected / INDEX_HTML).read_text(encoding="utf-8")
    boxes = page.split("<h2 id=")[1:]
    loop = next(section for section in boxes if section.startswith('"ds-0">loop'))
    accuracy = loop.split("<h3>Accuracy</h3>")[1].split("</table>")[0]
    assert _th_texts(accuracy) == ["method", "degradation", "seeds", "loop gap (m)", "ATE RMSE (m)", "status"]
    assert re.findall(r'<label title="(\w+)"><input type="checkbox" data-col="(\d+)" checked>', accuracy) == [
        ("loop_gap_m", "3"),
        ("ate_rmse_m", "4"),
    ]
    assert "Accuracy: Columns shown (--columns loop_gap_m,ate_rmse_m,per_scan_ms_median): loop gap (m); ATE" in page
    bare = next(section for section in boxes if section.startswith('"ds-1">bare'))
    table = bare.split("<h3>Accuracy</h3>")[1].split("</table>")[0]
    assert _th_texts(table) == ["method", "degradation", "seeds", "status"] and "colpick" not in table
    full = (whole / INDEX_HTML).read_text(encoding="utf-8")
    assert "Columns shown" not in full
    first = full.split("<h3>Accuracy</h3>")[1].split("</table>")[0]
    shown = ["ate_rmse_m", "rpe_frame_m", "rpe_frame_deg", "drift_10m_m", "drift_10m_deg", "loop_gap_m"]
    shown += ["orientation_deg", "updates_per_view"]  # the columns with a number on this loop
    assert _th_texts(first)[3:-1] == [METRIC_COLUMNS[key].header for key in shown]
    boxes = re.findall(r'<label title="(\w+)"><input type="checkbox" data-col="(\d+)" checked>', first)
    assert boxes == [(key, str(3 + i)) for i, key in enumerate(shown)]


@pytest.mark.slow
def test_the_quick_report_says_once_why_a_block_is_absent_and_writes_no_empty_page(whole: Path) -> None:
    text = (whole / "metrics.md").read_text(encoding="utf-8")
    bare = text.split("## bare")[1]
    notes = [line for line in bare.splitlines() if line.strip().startswith("- ")]
    relations = [c.header for c in METRIC_COLUMNS.values() if c.metric in ("relations", "relation_box")]
    places = [c.header for c in METRIC_COLUMNS.values() if c.metric == "places"]
    assert notes[0] == "- left out, n/a in every run of this dataset:"
    assert notes[3] == f"  - {'; '.join(relations).replace('>', '&gt;')} — the dataset has no ground-truth relations"
    # the method's own counters are absent for the metric's reason, not "no result.json value"
    assert notes[4] == f"  - {'; '.join(places)} — the method keeps no network of places (no places.json)"
    assert len(notes) == 5 and notes[1].endswith(f" — {NO_REFERENCE}") and "ATE RMSE (m); " in notes[1]
    assert len(set(notes)) == len(notes) and "result.json value" not in text
    assert "updates/view" in bare.split("\n\n")[2]  # the one number the bag has
    assert not (whole / STANDARD_PAGE).exists()  # a page of five "not measured" logs says nothing


#: Run after the page's own scripts: hide the first table's RPE column, sort the rows, show all columns again.
PROBE = """
<script>
(function () {
  var box = document.querySelector('details.colpick label[title="rpe_frame_m"] input');
  var table = box.closest(".table-box").querySelector("table"), col = parseInt(box.dataset.col, 10);
  function shown(c) {
    return Array.prototype.map.call(table.rows, function (row) { return getComputedStyle(row.cells[c]).display; });
  }
  var before = shown(col);
  box.click();
  var out = {header: table.rows[0].cells[col].textContent, label: box.parentNode.textContent.trim(),
             before: before, hidden: shown(col), left: shown(col - 1), right: shown(col + 1),
             width: table.rows[1].cells[col].getBoundingClientRect().width};
  table.rows[0].cells[2].click();
  out.sorted = shown(col);
  var others = document.querySelectorAll("table.sortable")[1];
  out.other = Array.prototype.map.call(others.rows, function (row) {
    return getComputedStyle(row.cells[col]).display;
  });
  box.closest("details").querySelector("button").click();
  out.again = shown(col);
  out.checked = box.checked;
  var pre = document.createElement("pre");
  pre.id = "probe";
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
})();
</script>
"""


@pytest.mark.slow
@pytest.mark.skipif(headless_chromium.browser() is None, reason=headless_chromium.NO_BROWSER)
def test_chromium_hides_a_column_header_and_every_cell_and_shows_it_again(whole: Path, tmp_path: Path) -> None:
    browser = headless_chromium.browser()
    assert browser is not None
    page = whole / "probed.html"  # in the report folder: the same relative links as index.html
    page.write_text(
        (whole / INDEX_HTML).read_text(encoding="utf-8").replace("</body>", PROBE + "</body>"), encoding="utf-8"
    )
    offline = headless_chromium.flags(tmp_path / "profile")  # every network request fails: the page needs none
    done = subprocess.run([browser, *offline, "--dump-dom", page.as_uri()], capture_output=True, text=True, timeout=120)
    found = re.search(r'<pre id="probe">(.*?)</pre>', done.stdout, re.S)
    assert found is not None, done.stderr[-2000:]
    probe = json.loads(html.unescape(found.group(1)))
    assert probe["header"] == probe["label"] == METRIC_COLUMNS["rpe_frame_m"].header
    rows = 3  # the header, the undegraded row and the noisy row (two seeds)
    assert len(probe["before"]) == len(probe["hidden"]) == rows and set(probe["before"]) == {"table-cell"}
    assert set(probe["hidden"]) == {"none"} and probe["width"] == 0  # the header and every cell of the column
    assert set(probe["left"]) == set(probe["right"]) == {"table-cell"}  # its neighbours stay
    assert set(probe["sorted"]) == {"none"}  # sorting the rows keeps the column hidden
    assert set(probe["other"]) == {"table-cell"}  # another table's column of the same place stays
    assert set(probe["again"]) == {"table-cell"} and probe["checked"] is True  # "show all"


def test_the_docs_list_every_valid_key_in_order() -> None:
    docs = Path(__file__).resolve().parents[3] / "docs" / "benchmarking.md"
    bullet = docs.read_text(encoding="utf-8").split("- **Column selection**")[1].split("\n- **")[0]
    keys = bullet.split("by key: ")[1].split(" (cost)")[0]
    assert re.findall(r"`(\w+)`", keys) == list(KNOWN)
