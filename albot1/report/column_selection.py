"""The report's column selection (``albot1 report --columns KEY,KEY``): which numbers its tables show.

The accuracy table has a column per number the metrics give (18 and more),
too wide for a paper or a screen; a reader usually wants three or four. The
selection names columns by their key (``ate_rmse_m``, ``per_scan_ms_median``:
the keys of :data:`~albot1.report.collect.METRIC_COLUMNS` and
:data:`~albot1.report.collect.COST_COLUMNS`), in the order they are to be
shown. It picks number columns only: the columns that say which row is which
(method, degradation, seeds) and the status are always shown, so a selection
can never hide a failure.

It applies to the aggregated tables in every format (``metrics`` and
``cost`` as Markdown, CSV, LaTeX and HTML); the one-row-per-cell files
(``cells.csv``, ``cells-cost.csv``) keep every column, so a selection never
removes a number from the report folder, and every table says so under its
title (:meth:`ColumnSelection.note`). A key the report does not know is an
error naming the closest keys and every valid one, before anything is
written.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from albot1.config.suggest import did_you_mean
from albot1.report.collect import Column
from albot1.report.errors import ReportError


@dataclass(frozen=True)
class ColumnSelection:
    """Column keys to show, in order; empty: every column (no selection)."""

    keys: tuple[str, ...] = ()

    @property
    def active(self) -> bool:
        """Whether the report shows only some columns."""
        return bool(self.keys)

    def pick(self, columns: Mapping[str, Column]) -> dict[str, Column]:
        """The columns of one table to show: the selected ones of ``columns``, in the selection's order."""
        if not self.keys:
            return dict(columns)
        return {key: columns[key] for key in self.keys if key in columns}

    def option(self) -> str:
        """The selection as typed on the command line (``--columns a,b``)."""
        return f"--columns {','.join(self.keys)}"

    def note(self, columns: Mapping[str, Column], table: str, every_cell: str) -> str | None:
        """One sentence for a table of ``columns``: what is shown, how much is hidden and where it all is.

        ``table``: the table's CSV file; ``every_cell``: the file of one row per cell that keeps every column
        of this table. None without a selection.
        """
        if not self.keys:
            return None
        shown = self.pick(columns)
        listed = "; ".join(column.header for column in shown.values()) if shown else "none"
        hidden = len(columns) - len(shown)
        return (
            f"Columns shown ({self.option()}): {listed}. Hidden here and in {table}: {hidden} of the "
            f"{len(columns)} number columns; {every_cell} has every column of every cell, and a report without "
            "--columns shows them all."
        )


#: No selection: every column.
ALL_COLUMNS = ColumnSelection()


def parse_columns(text: str, known: Mapping[str, Column]) -> ColumnSelection:
    """``KEY,KEY,...`` as a selection of the columns ``known`` (key -> column); ReportError for an unknown key.

    Spaces around a key are ignored and a key named twice is shown once. An
    empty list or an empty item (``a,,b``) is an error, as is a key the report
    does not know: the message suggests the closest keys (and the key of a
    column header typed instead of its key) and lists every valid key.
    """
    items = [item.strip() for item in text.split(",")]
    if not text.strip() or any(not item for item in items):
        raise ReportError(
            f"--columns {text!r}: expected column keys separated by commas, found an empty one; "
            f"valid keys: {', '.join(known)}"
        )
    for item in items:
        if item not in known:
            raise ReportError(f"--columns: {unknown_key(item, known)}")
    return ColumnSelection(tuple(dict.fromkeys(items)))


def unknown_key(name: str, known: Mapping[str, Column]) -> str:
    """``unknown column key 'x' (did you mean ...?); valid keys: ...`` -- every valid key, on one line."""
    by_header = {column.header.casefold(): key for key, column in known.items()}
    header_key = by_header.get(" ".join(name.split()).casefold())
    hint = f" (that is the header of {header_key!r}: name a column by its key)" if header_key else ""
    hint = hint or did_you_mean(name, list(known))
    return f"unknown column key {name!r}{hint}; valid keys: {', '.join(known)}"
