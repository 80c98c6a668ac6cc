"""The report's list of external methods: each file with its sha256, escaped for Markdown and HTML."""

from __future__ import annotations

from pathlib import Path

from albot1.bench.grid import Cell
from albot1.report.collect import CellRecord
from albot1.report.external_notes import external_entries, external_html, external_markdown


def _record(label: str, trajectory: str | None) -> CellRecord:
    cell = Cell(
        "s", "aces", "aces", "carto", label, "external", "none", 0, "k", "v", 1, 1,
        config={"sha256": "ab" * 32} if trajectory else None, trajectory=trajectory,
    )  # fmt: skip
    return CellRecord(cell, "done", Path("/x"), None, None, None)


def test_external_cells_are_listed_with_their_checksum_and_escaped() -> None:
    records = [_record("odometry", None), _record("carto|x (external)", "runs/<b>`c`.tum")]
    assert external_entries(records) == [("carto|x (external)", "aces", "runs/<b>`c`.tum", "ab" * 32)]
    lines = external_markdown(records)
    assert lines[2] == f"- carto\\|x (external) on aces: ``runs/<b>`c`.tum``, sha256 `{'ab' * 32}`"
    page = external_html(records)
    assert "runs/&lt;b&gt;`c`.tum" in page and "<b>" not in page
    assert external_markdown(records[:1]) == [] and external_html(records[:1]) == ""
