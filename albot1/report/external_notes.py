"""The report's note on external methods: which file each was scored from, with its sha256.

An external method (another system's trajectory files named by the suite,
:mod:`albot1.bench.external`) is shown in every table and plot under its
label ``NAME (external)``; this note says which file stood for it on each
dataset and the file's sha256 (as recorded in the run's ``result.json``
``config``), so a reader can check that the numbers belong to the file they
have. Timings and counters of such a run are "not measured".
"""

from __future__ import annotations

from html import escape

from albot1.report.collect import CellRecord
from albot1.report.markdown import code, text

TITLE = "External methods (other systems' trajectory files, scored here, not run)"


def external_entries(records: list[CellRecord]) -> list[tuple[str, str, str, str]]:
    """``(method label, dataset, file, sha256)`` per external cell, in suite order."""
    out = []
    for rec in records:
        if rec.cell.trajectory is None:
            continue
        sha = str((rec.cell.config or {}).get("sha256", ""))
        out.append((rec.cell.method_label, rec.cell.dataset_label, rec.cell.trajectory, sha))
    return out


def external_markdown(records: list[CellRecord]) -> list[str]:
    """Markdown lines (none when the suite has no external method)."""
    entries = external_entries(records)
    if not entries:
        return []
    return [
        f"## {TITLE}",
        "",
        *[
            f"- {text(label)} on {text(dataset)}: {code(path)}, sha256 {code(sha)}"
            for label, dataset, path, sha in entries
        ],
        "",
    ]


def external_html(records: list[CellRecord]) -> str:
    """An HTML section ('' when the suite has no external method)."""
    entries = external_entries(records)
    if not entries:
        return ""
    items = "".join(
        f"<li>{escape(label)} on {escape(dataset)}: <code>{escape(path)}</code>, sha256 <code>{escape(sha)}</code></li>"
        for label, dataset, path, sha in entries
    )
    return f'<h2 id="external">{escape(TITLE)}</h2><ul>{items}</ul>'
