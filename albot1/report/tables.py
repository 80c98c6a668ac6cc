"""Tables per dataset x method x degradation, aggregated over seeds: CSV for tools, Markdown and LaTeX for people.

Across seeds each number is the mean +/- the sample standard deviation
(ddof = 1), then the median, then the range (min-max) in brackets, the
rpg_trajectory_evaluation convention plus the project's standard (means as
well as medians): a mean alone hides one bad seed, and the median shows
whether it is one seed or all. All numbers of a table are given to
:data:`SIGNIFICANT` significant digits, the std, median and range with the
decimals of their mean, so a column reads evenly.

Every planned group is a row, also when no seed completed: its cells say
``failed`` and its status column gives the reason (``failed (timeout:
...)``), so a failure is as visible as a result. A number a run does not
have because the metric does not apply (no reference poses, a loop gap on
a route that never returns) is ``n/a``, with the reason under the table;
a column that applies to no run of a dataset is left out of its table and
named under it.

Accuracy (``metrics.*``) and cost (``cost.*``) are separate tables because
accuracy must be identical for identical inputs while cost varies with the
machine and its load; keeping them apart lets two runs be compared byte for
byte on the first.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from albot1.report.collect import (
    COST_COLUMNS,
    KEY_COLUMNS,
    METRIC_COLUMNS,
    CellRecord,
    Column,
    cell_columns,
    cell_rows,
    severity_order,
)
from albot1.report.column_selection import ALL_COLUMNS, ColumnSelection
from albot1.report.markdown import text as md_text
from albot1.report.number_text import EXAMPLE, SEEDS_LEGEND, SIGNIFICANT, stats_text
from albot1.report.paired_tables import PairedRow, intro, markdown_lines, no_pairs, paired_rows, write_paired_csv
from albot1.report.provenance import data_by_dataset, describe_data
from albot1.report.tuning import LEGEND, MARK, combined, marked, record_held_in

if TYPE_CHECKING:
    import pandas as pd

STATS = ("mean", "std", "median", "min", "max")
NOT_APPLICABLE = "n/a"
FAILED = "failed"
NOT_RUN = "not run"
#: Longest failure reason shown in a table cell (the index and cells.csv have it whole).
REASON_CHARS = 110


def cells_frame(records: list[CellRecord]) -> pd.DataFrame:
    """One row per cell (all statuses), in plan order."""
    import pandas as pd

    return pd.DataFrame(cell_rows(records), columns=cell_columns())  # the columns also when no cell was planned


def fields(column: str) -> list[str]:
    """The columns :func:`aggregate` makes for number ``column``, in table order: count, statistics, n/a reason."""
    return [f"{column}_n", *(f"{column}_{stat}" for stat in STATS), f"{column}_na"]


def pick(table: pd.DataFrame, every: dict[str, Column], columns: dict[str, Column]) -> pd.DataFrame:
    """``table`` (the :func:`aggregate` of ``every``) narrowed to ``columns`` (some of ``every``), in their order.

    Each number column's fields are computed from that column alone and the group columns (first in the
    table) from the cells alone, so this is :func:`aggregate` of ``columns`` without computing it again.
    """
    numbers = {name for column in every for name in fields(column)}
    groups = [name for name in table.columns if name not in numbers]
    return table[groups + [name for column in columns for name in fields(column) if name in table.columns]]


class Aggregates:
    """The cells of one set of records and their two aggregated tables (accuracy, cost), each computed once.

    A report reads the same tables three times (its table files, its figures, index.html), 5-20 s each for
    a suite of a few hundred cells, so :func:`albot1.report.index.build_report` makes one of these per set
    of records and hands it to each; a table is computed when first read (a report whose figures are all
    cached never computes the figures' one). Readers must not change the frames they are given.
    """

    def __init__(self, records: list[CellRecord]) -> None:
        self.records = records

    @cached_property
    def cells(self) -> pd.DataFrame:
        """:func:`cells_frame` with each cell's held-in mark (:func:`albot1.report.tuning.held_in`)."""
        cells = cells_frame(self.records)
        cells["held_in"] = [record_held_in(rec) for rec in self.records]
        return cells

    @cached_property
    def metrics(self) -> pd.DataFrame:
        """:func:`aggregate` of every accuracy column."""
        return aggregate(self.cells, METRIC_COLUMNS)

    @cached_property
    def cost(self) -> pd.DataFrame:
        """:func:`aggregate` of every cost column."""
        return aggregate(self.cells, COST_COLUMNS)


def aggregate(cells: pd.DataFrame, columns: dict[str, Column]) -> pd.DataFrame:
    """Every planned group (dataset x method x degradation): seed counts, status and mean/std/median/min/max.

    ``seeds`` counts the completed seeds the statistics are over;
    ``planned``, ``failed`` and ``not_run`` the cells of the group;
    ``status`` is ``ok`` or says what failed (``failed (kind: reason)``,
    ``1 of 3 failed (...)``). ``<column>_na`` holds the reason a column
    has no number in this group (not applicable), empty otherwise.
    """
    import pandas as pd

    if cells.empty:
        return pd.DataFrame(columns=[*KEY_COLUMNS, "seeds", "planned", "failed", "not_run", "status"])
    order = {name: i for i, name in enumerate(dict.fromkeys(cells["dataset"]))}
    methods = {name: i for i, name in enumerate(dict.fromkeys(cells["method"]))}
    degradations = {name: i for i, name in enumerate(severity_order(list(dict.fromkeys(cells["degradation"]))))}
    out_rows: list[dict[str, Any]] = []
    # each column as floats once (None -> NaN, as ``dropna().astype(float)`` of a group saw it), and the
    # statistics from numpy: the same numbers as pandas' (same sums, same order), without a Series per call
    numbers = {column: cells[column].to_numpy(dtype=np.float64, na_value=np.nan) for column in columns}
    reasons_of = {column: cells[f"{column}_na"].to_numpy(dtype=object) for column in columns if f"{column}_na" in cells}
    is_done = (cells["status"] == "done").to_numpy()
    groups = cells.groupby(list(KEY_COLUMNS), sort=False)
    for (dataset, method, degradation), group in groups:
        done = group[group["status"] == "done"]
        failed = group[group["status"] == "failed"]
        members = np.asarray(groups.indices[(dataset, method, degradation)], dtype=np.intp)
        rows = members[is_done[members]]
        row: dict[str, Any] = {
            "dataset": dataset,
            "method": method,
            "degradation": degradation,
            "seeds": int(done["seed"].nunique()),
            "planned": int(len(group)),
            "failed": int(len(failed)),
            "not_run": int((group["status"] == "not run").sum()),
            "status": _status(group, failed),
            "held_in": _held_in(group),
        }
        for column in columns:
            values: NDArray[np.float64] = numbers[column][rows]
            values = values[~np.isnan(values)]
            row[f"{column}_n"] = int(len(values))
            for stat in STATS:
                row[f"{column}_{stat}"] = _stat(values, stat)
            given = reasons_of[column][rows] if column in reasons_of else np.empty(0, dtype=object)
            reasons: list[str] = list(given[pd.notna(given)])
            row[f"{column}_na"] = Counter(reasons).most_common(1)[0][0] if reasons else None
        out_rows.append(row)
    table = pd.DataFrame(out_rows)
    rank = {"dataset": order, "method": methods, "degradation": degradations}
    table = table.sort_values(by=list(KEY_COLUMNS), key=lambda s: s.map(rank[str(s.name)]), kind="stable")
    return table.reset_index(drop=True)


def _held_in(group: pd.DataFrame) -> bool | None:
    """A row's held-in mark (:func:`albot1.report.tuning.combined` of its cells'; None, empty in CSV: unknown)."""
    return combined(group["held_in"]) if "held_in" in group else None


def _stat(values: NDArray[np.float64], stat: str) -> float:
    """One statistic of a group's numbers (NaN when there are none; the std needs two)."""
    if not len(values):
        return math.nan
    if stat == "std":
        return float(np.std(values, ddof=1)) if len(values) > 1 else math.nan
    return float(getattr(np, stat)(values))


def _status(group: pd.DataFrame, failed: pd.DataFrame) -> str:
    not_run = int((group["status"] == "not run").sum())
    if failed.empty and not not_run:
        return "ok"
    parts = []
    if not failed.empty:
        first = failed.iloc[0]
        reason = _short(f"{first['failure_kind']}: {first['reason']}")
        count = "" if len(failed) == len(group) else f"{len(failed)} of {len(group)} "
        parts.append(f"{count}failed ({reason})")
    if not_run:
        parts.append(f"{not_run} of {len(group)} not run")
    return "; ".join(parts)


def _short(text: str) -> str:
    flat = " ".join(str(text).split())
    return flat if len(flat) <= REASON_CHARS else flat[: REASON_CHARS - 1] + "…"


def cell_text(row: pd.Series, column: str) -> str:
    """The table text of ``column`` in aggregated ``row``: numbers, ``n/a``, ``failed`` or ``not run``."""
    mean = row[f"{column}_mean"]
    if isinstance(mean, float) and math.isnan(mean):
        if row["seeds"] == 0:
            return FAILED if row["failed"] else NOT_RUN
        return NOT_APPLICABLE
    n, seeds = int(row[f"{column}_n"]), int(row["seeds"])
    stat = {name: float(row[f"{column}_{name}"]) for name in STATS}
    text = stats_text(stat["mean"], stat["std"], stat["median"], stat["min"], stat["max"], n)
    # a mean over fewer seeds than the seeds column says (the metric is n/a in the others) must say so
    return text if n >= seeds else f"{text}, over {n} of {seeds} seeds"


def columns_present(group: pd.DataFrame, columns: dict[str, Column]) -> tuple[list[str], list[str]]:
    """(columns with a number in some row, columns that apply to no completed row) of one dataset."""
    present = [c for c in columns if group[f"{c}_mean"].notna().any()]
    absent = [c for c in columns if c not in present and group[f"{c}_na"].notna().any()]
    return present, absent


@dataclass(frozen=True)
class NaNote:
    """Why some columns of one dataset's table read ``n/a``: one reason, said once for all the columns it explains.

    A dataset without reference poses has a dozen columns that are n/a for
    the same reason; one line per column repeated it a dozen times.
    ``everywhere``: no completed run of the dataset has a number in these
    columns, so the table leaves them out.
    """

    headers: tuple[str, ...]
    reason: str
    everywhere: bool

    def text(self) -> str:
        """The columns and their reason as one line of text (Markdown and HTML escape it their way)."""
        return f"{'; '.join(self.headers)} — {self.reason}"


#: The lead of the notes on columns a dataset's table leaves out.
LEFT_OUT = "left out, n/a in every run of this dataset"


def na_outline(notes: list[NaNote]) -> list[tuple[str, list[str]]]:
    """The notes as list items with sub-items: ``n/a: ...`` each, then the left-out columns under one lead.

    One left-out reason is one line (``left out, ...: columns — reason``); several are sub-items of the lead,
    so that the lead is said once.
    """
    items: list[tuple[str, list[str]]] = [(f"n/a: {n.text()}", []) for n in notes if not n.everywhere]
    left_out = [n.text() for n in notes if n.everywhere]
    if len(left_out) == 1:
        items.append((f"{LEFT_OUT}: {left_out[0]}", []))
    elif left_out:
        items.append((f"{LEFT_OUT}:", left_out))
    return items


def na_notes(group: pd.DataFrame, columns: dict[str, Column], present: list[str], absent: list[str]) -> list[NaNote]:
    """The not-applicable notes of one dataset's table: the columns of each reason together, in column order.

    A column shown with some ``n/a`` cells gives the reasons of those cells;
    a column left out (:func:`columns_present`) the reasons of its runs.
    """
    grouped: dict[tuple[str, bool], list[str]] = {}
    for c in present:
        reasons = [str(r) for r in dict.fromkeys(group[f"{c}_na"].dropna())]
        if reasons and (group[f"{c}_n"] < group["seeds"]).any():
            grouped.setdefault(("; ".join(reasons), False), []).append(columns[c].header)
    for c in absent:
        reasons = [str(r) for r in dict.fromkeys(group[f"{c}_na"].dropna())]
        grouped.setdefault(("; ".join(reasons), True), []).append(columns[c].header)
    return [NaNote(tuple(headers), reason, everywhere) for (reason, everywhere), headers in grouped.items()]


def markdown(
    table: pd.DataFrame,
    columns: dict[str, Column],
    title: str,
    data: dict[str, dict[str, str]] | None = None,
    paired: list[PairedRow] | None = None,
    selected: str | None = None,
) -> str:
    """One Markdown table per dataset, each followed by its not-applicable notes and its paired comparisons.

    ``columns``: the number columns to show (a selection's :meth:`~ColumnSelection.pick`); ``selected``: the
    selection's note (:meth:`~albot1.report.column_selection.ColumnSelection.note`), stated under the title.
    ``data``: dataset label -> {file: short sha256} (:func:`albot1.report.provenance.data_by_dataset`), stated
    under each dataset's heading. ``paired``: the rows of :func:`albot1.report.paired_tables.paired_rows`.
    Names are written as text (:mod:`albot1.report.markdown`), never as HTML.
    """
    lines = [
        f"# {title}",
        "",
        f"Each number: {SEEDS_LEGEND}, e.g. `{EXAMPLE}` for seeds of 1, 2 and 10; one number when there is one "
        f"seed or all seeds agree; `over k of n seeds` when the metric does not apply to the others. "
        f"{SIGNIFICANT} significant digits. `n/a`: the metric does not apply to that run "
        "(the reason is under the table); `failed`: no seed completed (the status column says why).",
        "",
        *([md_text(selected), ""] if selected else []),
        *([LEGEND, ""] if any_held_in(table) else []),
        *([intro(), ""] if paired else [no_pairs(), ""] if paired is not None else []),
    ]
    if table.empty:
        return "\n".join([*lines, "No planned cells.", ""])
    for dataset, group in table.groupby("dataset", sort=False):
        present, absent = columns_present(group, columns)
        header = ["method", "degradation", "seeds", *[columns[c].header for c in present], "status"]
        lines += [
            f"## {md_text(dataset)}",
            "",
            *([f"Data: {md_text(describe_data(data[str(dataset)]))}.", ""] if data and str(dataset) in data else []),
            "| " + " | ".join(header) + " |",
            "|" + "|".join(["---"] * 3 + ["---:"] * len(present) + ["---"]) + "|",
        ]
        for _, row in group.iterrows():
            cells = [
                md_text(marked(str(row["method"]), bool(row.get("held_in", False)))),
                md_text(row["degradation"]),
                str(int(row["seeds"])),
                *[cell_text(row, c) for c in present],
                md_text(row["status"]),
            ]
            lines.append("| " + " | ".join(cells) + " |")
        notes = na_notes(group, columns, present, absent)
        lines.append("")
        for item, subitems in na_outline(notes):
            lines += [f"- {md_text(item)}", *[f"  - {md_text(sub)}" for sub in subitems]]
        lines += [""] if notes else []
        lines += markdown_lines(paired or [], str(dataset))
    return "\n".join(lines)


#: Characters LaTeX reads as markup, or that the default OT1 font encoding prints as another glyph
#: (``|`` as an em dash, ``<`` and ``>`` as inverted marks, ``"`` as a closing curly quote), and what to write.
#: ``\textbar``, ``\textless`` and ``\textgreater`` work in every encoding (the kernel's fallbacks);
#: ``\textquotedbl`` exists only with T1 (an error under OT1), so ``"`` is the typewriter font's straight
#: quote, character 34 in both OT1 and T1, which needs no package in a table pasted into any preamble.
_LATEX_ESCAPES = {
    "\\": r"\textbackslash{}",
    "&": r"\&",
    "%": r"\%",
    "$": r"\$",
    "#": r"\#",
    "_": r"\_",
    "{": r"\{",
    "}": r"\}",
    "~": r"\textasciitilde{}",
    "^": r"\textasciicircum{}",
    "|": r"\textbar{}",
    "<": r"\textless{}",
    ">": r"\textgreater{}",
    '"': r"{\ttfamily\char34}",
    "–": "--",
    "…": r"\dots{}",
}


def _latex_escape(text: str) -> str:
    """``text`` as LaTeX prints it literally (names of datasets, methods, degradations come from users).

    One line: a blank line inside a name was a ``\\par`` in a tabular cell or a caption, an error that
    stopped the paper's build.
    """
    return "".join(_LATEX_ESCAPES.get(ch, ch) for ch in " ".join(str(text).split()))


def latex(table: pd.DataFrame, columns: dict[str, Column], title: str, selected: str | None = None) -> str:
    """One booktabs ``table`` per dataset (``\\usepackage{booktabs}``), numbers as in the Markdown tables.

    ``columns`` and ``selected`` as for :func:`markdown` (the note becomes a comment line).
    """
    lines = [
        f"% {title}: mean $\\pm$ sample std over seeds, median (min--max); {SIGNIFICANT} significant digits.",
        "% Needs \\usepackage{booktabs}. n/a: the metric does not apply (see the Markdown table for the reason).",
        *([f"% {' '.join(selected.split())}"] if selected else []),
        *([f"% $^\\dagger$: {LEGEND.removeprefix(MARK).strip()}"] if any_held_in(table) else []),
        "",
    ]
    for dataset, group in table.groupby("dataset", sort=False):
        present, _ = columns_present(group, columns)
        spec = "ll" + "r" * len(present) + "l"
        header = ["method", "degradation", *[columns[c].header for c in present], "status"]
        lines += [
            "\\begin{table}[ht]",
            "\\centering\\small",
            f"\\caption{{{_latex_escape(title)}: {_latex_escape(str(dataset))}}}",
            f"\\begin{{tabular}}{{{spec}}}",
            "\\toprule",
            " & ".join(_latex_escape(h) for h in header) + " \\\\",
            "\\midrule",
        ]
        for _, row in group.iterrows():
            cells = [
                # the mark travels with the row: a row pasted into a paper keeps saying it was tuned on this log
                _latex_escape(row["method"]) + (" $^\\dagger$" if row.get("held_in") is True else ""),
                _latex_escape(row["degradation"]),
                *[cell_text(row, c).replace("±", "$\\pm$").replace("–", "--") for c in present],
                _latex_escape(row["status"]),
            ]
            lines.append(" & ".join(cells) + " \\\\")
        lines += ["\\bottomrule", "\\end{tabular}", "\\end{table}", ""]
    return "\n".join(lines)


def _csv_frame(table: pd.DataFrame) -> pd.DataFrame:
    """The aggregated table without the internal ``_n``/``_na`` helper columns, reasons kept as ``_na``."""
    return table[[c for c in table.columns if not c.endswith("_n")]]


def any_held_in(table: pd.DataFrame) -> bool:
    """Whether some row of an aggregated table is marked held-in (then the mark's legend is stated)."""
    return "held_in" in table and bool(table["held_in"].eq(True).any())


def write_tables(
    records: list[CellRecord],
    out: Path,
    paired: list[PairedRow] | None = None,
    selection: ColumnSelection = ALL_COLUMNS,
    aggregates: Aggregates | None = None,
) -> dict[str, Path]:
    """Write cells.csv, metrics.{csv,md,tex}, paired.csv and cost.{csv,md,tex} (+ cells-cost.csv) into ``out``.

    ``paired``: the metrics tables' paired comparisons when the caller has them (computed here otherwise).
    ``selection``: the number columns the metrics and cost tables show (all formats, CSV included); the
    one-row-per-cell files keep every column (:mod:`albot1.report.column_selection`). ``aggregates``: the
    caller's :class:`Aggregates` of ``records``, shared with its figures and page (made here otherwise).
    """
    out.mkdir(parents=True, exist_ok=True)
    paired = paired_rows(records) if paired is None else paired
    aggregates = Aggregates(records) if aggregates is None else aggregates
    cells = aggregates.cells
    written = {"cells.csv": out / "cells.csv"}
    helper = [c for c in cells.columns if c.endswith("_na")]
    cells.drop(columns=[*COST_COLUMNS, *helper]).to_csv(written["cells.csv"], index=False, float_format="%.9g")
    for name, every, whole, every_cell, title in (
        ("metrics", METRIC_COLUMNS, aggregates.metrics, "cells.csv", "Accuracy per dataset, method and degradation"),
        ("cost", COST_COLUMNS, aggregates.cost, "cells-cost.csv", "Cost per dataset, method and degradation"),
    ):
        columns, selected = selection.pick(every), selection.note(every, f"{name}.csv", every_cell)
        table = pick(whole, every, columns)
        paths = {ext: out / f"{name}.{ext}" for ext in ("csv", "md", "tex")}
        _csv_frame(table).to_csv(paths["csv"], index=False, float_format="%.9g")
        shown = paired if name == "metrics" else None
        page = markdown(table, columns, title, data_by_dataset(records), shown, selected)
        paths["md"].write_text(page, encoding="utf-8")
        paths["tex"].write_text(latex(table, columns, title, selected), encoding="utf-8")
        written.update({f"{name}.{ext}": path for ext, path in paths.items()})
    cost_cells = out / "cells-cost.csv"
    cells[["dataset", "method", "degradation", "seed", "status", "held_in", *COST_COLUMNS]].to_csv(
        cost_cells, index=False, float_format="%.9g"
    )
    written["cells-cost.csv"] = cost_cells
    written["paired.csv"] = write_paired_csv(paired, out)
    return written
