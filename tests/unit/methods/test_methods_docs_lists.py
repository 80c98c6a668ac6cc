"""Lists of methods and presets in the docs are checked against the registry, so they cannot drift.

A list in a Markdown page is marked ``<!-- registry: methods -->...<!-- /registry -->``
(every built-in method) or ``<!-- registry: presets METHOD -->...<!-- /registry -->``
(every preset of METHOD); the names inside are the backticked words.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from albot1.config.presets import preset_names
from albot1.methods.registry import BUILTIN_METHODS

ROOT = Path(__file__).resolve().parents[3]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
MARKED = re.compile(r"<!-- registry: (?P<what>methods|presets [a-z0-9-]+) -->(?P<body>.*?)<!-- /registry -->", re.S)


def marked_lists(text: str) -> list[tuple[str, list[str]]]:
    """(what, names) of every marked list in ``text``."""
    return [(m["what"], re.findall(r"`([^`]+)`", m["body"])) for m in MARKED.finditer(text)]


def expected(what: str) -> list[str]:
    if what == "methods":
        return [spec.name for spec in BUILTIN_METHODS]
    return preset_names(what.split()[1])


def _lists() -> list[tuple[str, str, list[str]]]:
    return [(page.name, what, names) for page in PAGES for what, names in marked_lists(page.read_text("utf-8"))]


@pytest.mark.parametrize(("page", "what", "names"), _lists(), ids=lambda v: str(v)[:30])
def test_a_marked_list_names_exactly_the_registered_ones(page: str, what: str, names: list[str]) -> None:
    assert sorted(set(names)) == sorted(expected(what)), f"{page}: the list of {what}"


def test_architecture_marks_its_method_and_preset_lists() -> None:
    found = {what for page, what, _ in _lists() if page == "architecture.md"}
    assert {"methods", "presets albot1"} <= found


def test_the_check_fails_on_a_missing_name() -> None:
    text = "<!-- registry: presets albot1 -->`default`, `thesis`, `exact`, `literal`<!-- /registry -->"
    [(what, names)] = marked_lists(text)
    assert sorted(names) != sorted(expected(what))  # `plus` is missing
