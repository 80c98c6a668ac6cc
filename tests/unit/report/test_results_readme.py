"""The README's results block is what the committed results record renders: no README number can be stale."""

from __future__ import annotations

from pathlib import Path

from albot1.report.results_data import load_data
from albot1.report.results_page import readme_block, render_page, render_readme_block

ROOT = Path(__file__).resolve().parents[3]
RECORD = ROOT / "docs" / "results" / "results.json"


def test_readme_block_equals_the_committed_record() -> None:
    """Before the first `make bench` record is committed, the block must be the placeholder (and say so)."""
    data = load_data(RECORD)
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert readme_block(readme, "README.md") == render_readme_block(data)


def test_results_page_equals_the_committed_record() -> None:
    data = load_data(RECORD)
    page = ROOT / "docs" / "results.md"
    if data is None:
        assert not page.exists(), "docs/results.md is committed without docs/results/results.json"
        return
    assert page.read_text(encoding="utf-8") == render_page(data)
    for name in data.figures:
        assert (RECORD.parent / name).is_file(), f"docs/results/{name} is named by the record but missing"
