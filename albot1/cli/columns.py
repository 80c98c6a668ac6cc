"""Plain-text listings of the CLI (``albot1 methods``, ``albot1 datasets list``): columns as wide as their cells.

Fixed widths (``{name:12s}``) misalign every row whose name is longer than
the width guessed for it (``albot1-places``, ``synthetic-office-startstop-10deg``);
the widths here are measured from the rows, so a plugin's or a new dataset's
long name moves the column instead of pushing its row out of line.
"""

from __future__ import annotations

from collections.abc import Sequence

#: Spaces between two columns.
GAP = "  "


def aligned(rows: Sequence[Sequence[str]]) -> list[str]:
    """Each row as one line, every column but the last padded to its widest cell (trailing spaces removed)."""
    if not rows:
        return []
    count = max(len(row) for row in rows)
    widths = [max((len(row[i]) for row in rows if i < len(row)), default=0) for i in range(count - 1)]
    lines = []
    for row in rows:
        cells = [cell.ljust(widths[i]) if i < count - 1 else cell for i, cell in enumerate(row)]
        lines.append(GAP.join(cells).rstrip())
    return lines
