"""Report tables: aggregation over seeds, formatting, and the split of accuracy and cost."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest

from albot1.bench.grid import Cell
from albot1.bench.store import Failure
from albot1.metrics.ate import ate as ate_block
from albot1.metrics.record import MetricsRecord
from albot1.metrics.registry import metric_registry
from albot1.metrics.updates import update_counts
from albot1.records import ResultRecord, check_number_path, parse_record
from albot1.report.collect import COST_COLUMNS, METRIC_COLUMNS, SOURCE_MODELS, CellRecord, Column
from albot1.report.html import table_html
from albot1.report.markdown import text as md_text
from albot1.report.number_text import fmt, stats_text
from albot1.report.tables import (
    Aggregates,
    aggregate,
    cell_text,
    cells_frame,
    markdown,
    pick,
    write_tables,
)

if TYPE_CHECKING:
    import pandas as pd

METRIC_NAMES = metric_registry().names

RUN = {
    "key": "k",
    "method": "odometry",
    "dataset": "w",
    "preset": "default",
    "degradation": "none",
    "seed": 0,
    "scans": 10,
    "has_reference": True,
}


def metrics_record(ate_rmse_m: float | None) -> MetricsRecord:
    """A valid metrics.json: an ATE block with the given RMSE (or none), 1 update per 2 views, the rest absent."""
    data: dict[str, Any] = {"run": RUN}
    for name in METRIC_NAMES:
        data[name], data[f"{name}_reason"] = None, "not computed in this test"
    if ate_rmse_m is not None:
        poses = np.column_stack([np.arange(5.0), np.zeros(5), np.zeros(5)])
        data["ate"], data["ate_reason"] = {**ate_block(poses, poses), "rmse_m": ate_rmse_m}, None
    data["updates"], data["updates_reason"] = update_counts({"views": 2, "updates": 1}), None
    return parse_record(MetricsRecord, data, "test metrics")


def result_record(ms: float) -> ResultRecord:
    timing = {
        "per_scan_ms_median": ms,
        "per_scan_ms_p95": 2 * ms,
        "per_scan_ms_mean": ms,
        "finish_s": 0.0,
        "total_s": 0.01,
        "wall_s": 0.02,
        "peak_mb": 100.0,
    }
    data = {
        **{k: v for k, v in RUN.items() if k != "has_reference"},
        "config": {},
        "versions": {"code": "v"},
        "dataset_info": {"source": "", "format": "", "odometry_source": "", "reference_source": ""},
        "counters": {"views": 10, "updates": 5},
        "timing": timing,
        "map_file": "map.npz",
        "has_reference": True,
        "relations": 0,
    }
    return parse_record(ResultRecord, data, "test result")


def record(
    dataset: str, method: str, degradation: str, seed: int, ate: float | None, *, status: str = "done", ms: float = 1.0
) -> CellRecord:
    cell = Cell(
        suite="t",
        dataset=dataset,
        dataset_label=dataset,
        method=method,
        method_label=method,
        preset="default",
        degradation=degradation,
        seed=seed,
        key=f"{dataset}-{method}-{degradation}-{seed}",
        code_version="v",
        time_s=10,
        memory_mb=100,
    )
    if status != "done":
        return CellRecord(
            cell,
            status,
            Path("/nonexistent"),
            None,
            None,
            Failure("RuntimeError: boom", "exception", 2, 0.1, None) if status == "failed" else None,
        )
    return CellRecord(cell, "done", Path("/nonexistent"), result_record(ms), metrics_record(ate), None)


def test_every_report_column_names_a_numeric_field_of_its_record() -> None:
    for name, column in {**METRIC_COLUMNS, **COST_COLUMNS}.items():
        check_number_path(SOURCE_MODELS[column.source], column.path)  # raises KeyError naming the path
        assert column.header, name


@pytest.mark.parametrize(
    ("source", "path", "problem"),
    [
        ("metrics", "ate.rmse", "no field 'ate.rmse'"),  # a typo
        ("metrics", "ate_rmse_m", "no field 'ate_rmse_m'"),
        ("result", "timing.per_scan_median_ms", "no field 'timing.per_scan_median_ms'"),
        ("metrics", "ate.alignment", "not a number"),  # a field, but text
        ("metrics", "ate.rotation", "not a number"),  # a block, not a number
        ("attempt", "host", "not a number"),
    ],
)
def test_a_column_naming_no_numeric_field_fails_when_defined(source: Any, path: str, problem: str) -> None:
    with pytest.raises(KeyError, match=problem):
        Column(source, path, "header")


def test_columns_read_numbers_and_leave_not_applicable_cells_empty() -> None:
    rec = record("w", "odometry", "none", 0, 0.25, ms=3.0)
    assert METRIC_COLUMNS["ate_rmse_m"].value(rec) == 0.25
    assert METRIC_COLUMNS["updates_per_view"].value(rec) == 0.5
    assert COST_COLUMNS["per_scan_ms_p95"].value(rec) == 6.0
    assert METRIC_COLUMNS["relation_m"].value(rec) is None  # relations: null with a reason
    assert COST_COLUMNS["cell_s"].value(rec) is None  # no attempt.json
    assert Column("result", "counters.views", "views").value(rec) == 10.0  # method counters: any key
    assert Column("result", "counters.nodes", "nodes").value(rec) is None
    assert METRIC_COLUMNS["ate_rmse_m"].value(record("w", "odometry", "none", 0, None)) is None


def test_aggregate_over_seeds_mean_std_median_min_max() -> None:
    records = [record("w", "odometry", "gauss:0.1:1", s, ate) for s, ate in ((0, 1.0), (1, 2.0), (2, 6.0))]
    records += [record("w", "odometry", "none", 0, 0.5), record("w", "odometry", "none", 1, None, status="failed")]
    table = aggregate(cells_frame(records), METRIC_COLUMNS)
    assert list(table["degradation"]) == ["none", "gauss:0.1:1"]  # by severity, whatever the plan order
    swept = table.iloc[1]
    assert (swept["seeds"], swept["planned"], swept["failed"], swept["status"]) == (3, 3, 0, "ok")
    stats = [swept[f"ate_rmse_m_{s}"] for s in ("mean", "median", "min", "max")]
    assert stats == [3.0, 2.0, 1.0, 6.0]
    assert swept["ate_rmse_m_std"] == pytest.approx(np.std([1.0, 2.0, 6.0], ddof=1))  # the sample std over seeds
    assert cell_text(swept, "ate_rmse_m") == "3.00 ± 2.65, median 2.00 (1.00–6.00)"
    single = table.iloc[0]
    assert (single["seeds"], single["planned"], single["failed"]) == (1, 2, 1)  # the failed seed is not averaged in
    assert single["status"] == "1 of 2 failed (exception: RuntimeError: boom)"
    assert cell_text(single, "ate_rmse_m") == "0.500"


def test_aggregates_computes_each_table_once_and_only_when_read(monkeypatch: pytest.MonkeyPatch) -> None:
    import albot1.report.tables as tables

    calls: list[tuple[str, ...]] = []
    compute = tables.aggregate

    def counted(cells: pd.DataFrame, columns: dict[str, Column]) -> pd.DataFrame:
        calls.append(tuple(columns))
        return compute(cells, columns)

    monkeypatch.setattr(tables, "aggregate", counted)
    records = [record("w", "odometry", "none", s, ate) for s, ate in ((0, 1.0), (1, 3.0))]
    shared = Aggregates(records)
    assert calls == []  # nothing computed until read
    assert shared.metrics is shared.metrics and shared.metrics.loc[0, "ate_rmse_m_mean"] == 2.0
    assert calls == [tuple(METRIC_COLUMNS)]
    assert list(shared.cells["held_in"]) == [False, False]
    assert shared.cost is shared.cost
    assert calls == [tuple(METRIC_COLUMNS), tuple(COST_COLUMNS)]


@pytest.mark.parametrize("keys", [["ate_rmse_m"], ["loop_gap_m", "ate_rmse_m"], []])
def test_a_picked_aggregate_is_the_aggregate_of_the_picked_columns(keys: list[str]) -> None:
    import pandas as pd  # here, not at collection: pandas costs every test run's collection

    records = [
        record("w", "odometry", "none", 0, 1.0),
        record("w", "odometry", "gauss:0.1:1", 1, None),
        record("w", "odometry", "gauss:0.1:1", 2, 2.5),
        record("v", "odometry", "none", 0, 0.5, status="failed"),
    ]
    cells = cells_frame(records)
    picked = {key: METRIC_COLUMNS[key] for key in keys}
    whole = aggregate(cells, METRIC_COLUMNS)
    pd.testing.assert_frame_equal(pick(whole, METRIC_COLUMNS, picked), aggregate(cells, picked))
    empty = cells_frame([])
    pd.testing.assert_frame_equal(
        pick(aggregate(empty, METRIC_COLUMNS), METRIC_COLUMNS, picked), aggregate(empty, picked)
    )


@pytest.mark.parametrize(
    ("mean", "std", "median", "low", "high", "n", "text"),
    [
        (0.0456, 0.0012, 0.0459, 0.0441, 0.0467, 3, "0.0456 ± 0.0012, median 0.0459 (0.0441–0.0467)"),
        (36.14, 4.21, 36.7, 31.5, 40.2, 3, "36.1 ± 4.2, median 36.7 (31.5–40.2)"),
        # >= 3 digits before the point: no decimals
        (1234.5, 10.0, 1234.5, 1220.0, 1250.0, 2, "1234 ± 10, median 1234 (1220–1250)"),
        (9.9996, 0.0, 9.9996, 9.9996, 9.9996, 3, "10.0"),  # rounded first: 10.0, not 10.00; equal seeds: one number
        # perfect odometry
        (2.5e-10, 1e-10, 2e-10, 1e-10, 4e-10, 3, "2.50e-10 ± 1.00e-10, median 2.00e-10 (1.00e-10–4.00e-10)"),
        (0.0, 0.0, 0.0, 0.0, 0.0, 1, "0.00"),
    ],
)
def test_numbers_have_three_significant_digits_and_the_spread_the_decimals_of_the_mean(
    mean: float, std: float, median: float, low: float, high: float, n: int, text: str
) -> None:
    assert stats_text(mean, std, median, low, high, n) == text


@pytest.mark.parametrize(
    ("mean", "std", "median", "low", "high", "text"),
    [
        # seeds 0.6 m apart around 1234 m: "± 0" said the seeds agreed while (1234–1235) said they did not
        (1234.5, 0.4243, 1234.5, 1234.2, 1234.8, "1234 ± 0.4, median 1234 (1234–1235)"),
        (5.0012, 0.0021, 5.0012, 4.9997, 5.0027, "5.00 ± 0.002, median 5.00 (5.00–5.00)"),
        (5.0, 0.0004, 5.0, 4.9997, 5.0003, "5.00 ± 4.00e-04, median 5.00 (5.00–5.00)"),
    ],
)
def test_a_spread_that_rounds_to_zero_at_the_decimals_of_the_mean_gets_its_own_digits(
    mean: float, std: float, median: float, low: float, high: float, text: str
) -> None:
    assert stats_text(mean, std, median, low, high, 2) == text


def test_a_number_that_rounds_to_zero_reads_without_a_minus_sign() -> None:
    """A seed of -0.001 shown at two decimals read "-0.00": a negative number where none was."""
    assert stats_text(5.0, 5.0, 5.0, -0.001, 10.0, 3) == "5.00 ± 5.00, median 5.00 (0.00–10.00)"
    assert (fmt(-0.0, 2), fmt(-0.004, 2), fmt(-0.006, 2), fmt(-1e-5, None)) == ("0.00", "0.00", "-0.01", "-1.00e-05")


def test_a_cell_over_seeds_shows_the_median_beside_the_mean_in_md_tex_and_html(tmp_path: Path) -> None:
    """Seeds of 1, 2 and 10 m: the mean (4.33) says little of the typical seed, the median (2.00) does.

    The standard asks for means as well as medians; the median was computed but reached only the CSV.
    """
    records = [record("w", "odometry", "none", s, ate) for s, ate in ((0, 1.0), (1, 2.0), (2, 10.0))]
    written = write_tables(records, tmp_path)
    md = written["metrics.md"].read_text()
    assert "| odometry | none | 3 | 4.33 ± 4.93, median 2.00 (1.00–10.00) | 0.500 | ok |" in md
    assert "Each number: mean ± sample std over the completed seeds, their median, then (min–max), e.g. " in md
    assert "`4.33 ± 4.93, median 2.00 (1.00–10.00)` for seeds of 1, 2 and 10; one number when" in md
    tex = written["metrics.tex"].read_text()
    assert "odometry & none & 4.33 $\\pm$ 4.93, median 2.00 (1.00--10.00) & 0.500 & ok \\\\" in tex
    assert "mean $\\pm$ sample std over seeds, median (min--max); 3 significant digits." in tex
    csv = written["metrics.csv"].read_text().splitlines()
    header, row = csv[0].split(","), csv[1].split(",")
    assert row[header.index("ate_rmse_m_median")] == "2"
    html = table_html(aggregate(cells_frame(records), METRIC_COLUMNS), METRIC_COLUMNS, {})
    assert '<td class="num" data-v="4.33333333333">4.33 ± 4.93, median 2.00 (1.00–10.00)</td>' in html


def test_a_group_whose_seeds_all_failed_is_a_row_marked_failed_with_the_reason() -> None:
    records = [record("w", "odometry", "none", 0, 0.25), record("w", "x", "none", 0, None, status="failed")]
    text = markdown(aggregate(cells_frame(records), METRIC_COLUMNS), METRIC_COLUMNS, "T")
    failed_row = next(line for line in text.splitlines() if line.startswith("| x |"))
    assert failed_row.startswith("| x | none | 0 | failed |")
    assert failed_row.endswith("| failed (exception: RuntimeError: boom) |")


def test_not_applicable_numbers_say_n_a_with_the_reason_under_the_table() -> None:
    records = [record("w", "odometry", "none", 0, 0.25), record("w", "odometry", "thesis", 0, None)]
    text = markdown(aggregate(cells_frame(records), METRIC_COLUMNS), METRIC_COLUMNS, "T")
    assert "| odometry | thesis | 1 | n/a |" in text
    notes = [line for line in text.splitlines() if line.startswith("- ")]
    left_out = [c.header for k, c in METRIC_COLUMNS.items() if k not in ("ate_rmse_m", "updates_per_view")]
    assert notes == [  # one line per reason: the 21 columns no run has share theirs
        "- n/a: ATE RMSE (m) — not computed in this test",
        f"- left out, n/a in every run of this dataset: {md_text('; '.join(left_out))} — not computed in this test",
    ]


def test_markdown_omits_columns_empty_for_a_dataset() -> None:
    records = [record("w", "odometry", "none", 0, None), record("v", "odometry", "none", 0, 0.25)]
    text = markdown(aggregate(cells_frame(records), METRIC_COLUMNS), METRIC_COLUMNS, "T")
    section_w = text.split("## w")[1].split("## v")[0]
    assert "ATE RMSE" not in section_w.split("\n\n")[1] and "updates/view" in section_w
    assert "| odometry | none | 1 | 0.250 | 0.500 | ok |" in text.split("## v")[1]


def test_latex_tables_are_booktabs_with_escaped_labels(tmp_path: Path) -> None:
    records = [record("w_1", "odometry", "gauss:0.1:1", s, ate) for s, ate in ((0, 1.0), (1, 2.0))]
    written = write_tables(records, tmp_path)
    tex = written["metrics.tex"].read_text()
    assert (
        "\\toprule" in tex
        and "\\bottomrule" in tex
        and "\\caption{Accuracy per dataset, method and degradation: w\\_1}" in tex
    )
    assert "odometry & gauss:0.1:1 & 1.50 $\\pm$ 0.71, median 1.50 (1.00--2.00)" in tex


def test_latex_escapes_every_character_tex_or_ot1_would_misprint(tmp_path: Path) -> None:
    """``| < > "`` printed as other glyphs under OT1 (an em dash, inverted marks, a curly quote)."""
    name = 'a|b<c>"d" \\&%$#_{}~^e'
    written = write_tables([record(name, "odometry", "none", 0, 1.0)], tmp_path)
    caption = next(line for line in written["metrics.tex"].read_text().splitlines() if line.startswith("\\caption"))
    assert caption == (
        "\\caption{Accuracy per dataset, method and degradation: "
        "a\\textbar{}b\\textless{}c\\textgreater{}{\\ttfamily\\char34}d{\\ttfamily\\char34} "
        "\\textbackslash{}\\&\\%\\$\\#\\_\\{\\}\\textasciitilde{}\\textasciicircum{}e}"
    )


def test_write_tables_keeps_cost_out_of_the_accuracy_files(tmp_path: Path) -> None:
    import pandas as pd

    records = [record("w", "odometry", "none", 0, 0.5, ms=3.0), record("w", "x", "none", 0, None, status="failed")]
    written = write_tables(records, tmp_path)
    metrics = pd.read_csv(written["metrics.csv"])
    cells = pd.read_csv(written["cells.csv"])
    cost = pd.read_csv(written["cost.csv"])
    assert not any(c.startswith(tuple(COST_COLUMNS)) for c in metrics.columns)
    assert not set(COST_COLUMNS) & set(cells.columns)
    assert cost.loc[0, "per_scan_ms_median_mean"] == 3.0
    assert list(cells["status"]) == ["done", "failed"] and cells.loc[1, "reason"] == "RuntimeError: boom"
    assert list(metrics["status"]) == ["ok", "failed (exception: RuntimeError: boom)"]


@pytest.mark.parametrize(
    ("value", "places", "text"),
    [(1e308, 0, "1.00e+308"), (-2.5e6, 3, "-2.50e+06"), (999999.4, 0, "999999"), (0.1234, 4, "0.1234")],
)
def test_a_huge_number_is_scientific_not_hundreds_of_digits(value: float, places: int, text: str) -> None:
    """A diverged run's 1e308 m filled a table cell with 309 digits."""
    assert fmt(value, places) == text


def test_a_method_name_with_a_backslash_pipe_or_emphasis_marks_stays_one_literal_markdown_cell(
    tmp_path: Path,
) -> None:
    """``a\\|b`` was written ``a\\\\|b``: an escaped backslash, then a pipe that split the row into one more cell;
    ``*x*`` and ``_y_`` were shown in italics, ``~~z~~`` struck through."""
    name = "a\\|b *x* _y_ ~~z~~"
    written = write_tables([record("w", name, "none", 0, 1.0)], tmp_path)
    row = next(line for line in written["metrics.md"].read_text().splitlines() if line.startswith("| a"))
    assert row.startswith("| a\\\\\\|b \\*x\\* \\_y\\_ \\~\\~z\\~\\~ | none | 1 | ")


def test_a_blank_line_in_a_name_is_no_paragraph_break_in_the_latex_table(tmp_path: Path) -> None:
    """A ``\\par`` in a caption or a tabular cell stops LaTeX with an error."""
    written = write_tables([record("w\n\nx", "odo\n\nmetry", "none", 0, 1.0)], tmp_path)
    tex = written["metrics.tex"].read_text()
    assert "\\caption{Accuracy per dataset, method and degradation: w x}" in tex
    assert "odo metry & none & " in tex


def test_a_mean_over_fewer_seeds_than_the_row_counts_says_over_how_many_and_why_in_md_and_tex(tmp_path: Path) -> None:
    """3 completed seeds, ATE n/a in one: the row read ``3 | 1.50 ± 0.71`` (a mean over 2) with no n/a note."""
    records = [record("w", "odometry", "none", s, ate) for s, ate in ((0, 1.0), (1, 2.0), (2, None))]
    written = write_tables(records, tmp_path)
    md = written["metrics.md"].read_text()
    assert "| odometry | none | 3 | 1.50 ± 0.71, median 1.50 (1.00–2.00), over 2 of 3 seeds | 0.500 | ok |" in md
    assert "- n/a: ATE RMSE (m) — not computed in this test" in md
    tex = written["metrics.tex"].read_text()
    assert "odometry & none & 1.50 $\\pm$ 0.71, median 1.50 (1.00--2.00), over 2 of 3 seeds & 0.500 & ok \\\\" in tex
