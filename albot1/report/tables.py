"""Tables per dataset x method x degradation, aggregated over seeds (CSV for tools, Markdown for people).

Across seeds each number is given as mean, median and (min-max), the
rpg_trajectory_evaluation convention: a mean alone hides one bad seed.
Accuracy (``metrics.*``) and cost (``cost.*``) are separate tables because
accuracy must be identical for identical inputs while cost varies with the
machine and its load; keeping them apart lets two runs be compared byte for
byte on the first.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from albot1.report.collect import (
    COST_COLUMNS,
    KEY_COLUMNS,
    METRIC_COLUMNS,
    CellRecord,
    Column,
    cell_rows,
    severity_order,
)

if TYPE_CHECKING:
    import pandas as pd

STATS = ("mean", "median", "min", "max")


def cells_frame(records: list[CellRecord]) -> pd.DataFrame:
    """One row per cell (all statuses), in plan order."""
    import pandas as pd

    return pd.DataFrame(cell_rows(records))


def aggregate(cells: pd.DataFrame, columns: dict[str, Column]) -> pd.DataFrame:
    """Completed cells grouped by dataset x method x degradation: n seeds and mean/median/min/max per column."""
    import pandas as pd

    done = cells[cells["status"] == "done"]
    out_rows: list[dict[str, Any]] = []
    if done.empty:
        return pd.DataFrame(columns=[*KEY_COLUMNS, "seeds"])
    order = {name: i for i, name in enumerate(dict.fromkeys(cells["dataset"]))}
    methods = {name: i for i, name in enumerate(dict.fromkeys(cells["method"]))}
    degradations = {name: i for i, name in enumerate(severity_order(list(dict.fromkeys(cells["degradation"]))))}
    for (dataset, method, degradation), group in done.groupby(list(KEY_COLUMNS), sort=False):
        row: dict[str, Any] = {
            "dataset": dataset,
            "method": method,
            "degradation": degradation,
            "seeds": int(group["seed"].nunique()),
        }
        for column in columns:
            values = group[column].dropna().astype(float)
            for stat in STATS:
                row[f"{column}_{stat}"] = float(getattr(values, stat)()) if len(values) else math.nan
        out_rows.append(row)
    table = pd.DataFrame(out_rows)
    rank = {"dataset": order, "method": methods, "degradation": degradations}
    table = table.sort_values(by=list(KEY_COLUMNS), key=lambda s: s.map(rank[str(s.name)]), kind="stable")
    table = table.reset_index(drop=True)
    return table


def _fmt(value: float) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    magnitude = abs(value)
    if magnitude >= 100:
        return f"{value:.0f}"
    if magnitude >= 10:
        return f"{value:.1f}"
    return f"{value:.3f}" if magnitude >= 0.01 or magnitude == 0 else f"{value:.2g}"


def cell_text(row: pd.Series, column: str) -> str:
    """``mean`` for one seed, else ``mean / median (min–max)``."""
    mean = row[f"{column}_mean"]
    if isinstance(mean, float) and math.isnan(mean):
        return "–"
    if row["seeds"] <= 1 or row[f"{column}_min"] == row[f"{column}_max"]:
        return _fmt(mean)
    return f"{_fmt(mean)} / {_fmt(row[f'{column}_median'])} ({_fmt(row[f'{column}_min'])}–{_fmt(row[f'{column}_max'])})"


def markdown(table: pd.DataFrame, columns: dict[str, Column], title: str) -> str:
    """One Markdown table per dataset; columns that are empty for a dataset are left out."""
    lines = [
        f"# {title}",
        "",
        "Each number: mean over seeds, then median (min–max) when seeds differ. "
        "`–`: not computable for this run (see the run's metrics.json for the reason).",
        "",
    ]
    if table.empty:
        return "\n".join([*lines, "No completed cells.", ""])
    for dataset, group in table.groupby("dataset", sort=False):
        present = [c for c in columns if group[f"{c}_mean"].notna().any()]
        header = ["method", "degradation", "seeds", *[columns[c].header for c in present]]
        lines += [
            f"## {dataset}",
            "",
            "| " + " | ".join(header) + " |",
            "|" + "|".join(["---"] * 3 + ["---:"] * len(present)) + "|",
        ]
        for _, row in group.iterrows():
            cells = [
                str(row["method"]),
                str(row["degradation"]),
                str(int(row["seeds"])),
                *[cell_text(row, c) for c in present],
            ]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    return "\n".join(lines)


def write_tables(records: list[CellRecord], out: Path) -> dict[str, Path]:
    """Write cells.csv, metrics.{csv,md} and cost.{csv,md} into ``out``; returns name -> path."""
    out.mkdir(parents=True, exist_ok=True)
    cells = cells_frame(records)
    written = {"cells.csv": out / "cells.csv"}
    cells.drop(columns=list(COST_COLUMNS)).to_csv(written["cells.csv"], index=False, float_format="%.9g")
    for name, columns, title in (
        ("metrics", METRIC_COLUMNS, "Accuracy per dataset, method and degradation"),
        ("cost", COST_COLUMNS, "Cost per dataset, method and degradation"),
    ):
        table = aggregate(cells, columns)
        csv_path, md_path = out / f"{name}.csv", out / f"{name}.md"
        table.to_csv(csv_path, index=False, float_format="%.9g")
        md_path.write_text(markdown(table, columns, title), encoding="utf-8")
        written[f"{name}.csv"], written[f"{name}.md"] = csv_path, md_path
    cost_cells = out / "cells-cost.csv"
    cells[["dataset", "method", "degradation", "seed", "status", *COST_COLUMNS]].to_csv(
        cost_cells, index=False, float_format="%.9g"
    )
    written["cells-cost.csv"] = cost_cells
    return written
