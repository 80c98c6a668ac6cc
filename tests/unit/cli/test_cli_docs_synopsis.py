"""The command synopses of the docs name every option the commands take, so a new option cannot go unlisted.

`docs/benchmarking.md` ("Commands") and `docs/formats.md` (`albot1 convert`) each show a synopsis in a fenced block;
`albot1 bench --retry-failed` and `albot1 report --force` were missing from the first one.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import typer

from albot1.cli.app import app

ROOT = Path(__file__).resolve().parents[3]


def synopsis(page: str, command: str) -> str:
    """The synopsis of ``albot1 COMMAND`` in ``docs/PAGE``: its line in a fenced block and the indented lines after."""
    lines: list[str] = []
    fenced = False
    for line in (ROOT / "docs" / page).read_text("utf-8").splitlines():
        if line.startswith("```"):
            fenced = not fenced
            if lines:
                break
            continue
        if not fenced:
            continue
        if lines and line.startswith(" "):
            lines.append(line)
        elif lines:
            break
        elif re.match(rf"albot1 {command} [A-Z\[]", line):
            lines.append(line)
    assert lines, f"docs/{page}: no synopsis of albot1 {command}"
    return " ".join(lines)


def options(command: str) -> list[tuple[str, ...]]:
    """Each option of ``albot1 COMMAND`` as all its spellings (``--jobs``/``-j``, ``--progress``/``--no-progress``)."""
    found = getattr(typer.main.get_command(app), "commands", {})[command]
    return [
        (*param.opts, *param.secondary_opts)
        for param in found.params
        if param.param_type_name == "option" and param.name != "help"
    ]


@pytest.mark.parametrize(
    ("page", "command"), [("benchmarking.md", "bench"), ("benchmarking.md", "report"), ("formats.md", "convert")]
)
def test_a_synopsis_names_every_option_of_its_command(page: str, command: str) -> None:
    text = synopsis(page, command)
    for spellings in options(command):
        named = any(re.search(rf"(?<![\w-]){re.escape(s)}(?![\w-])", text) for s in spellings)
        assert named, f"docs/{page}: {'/'.join(spellings)} of albot1 {command} is not in its synopsis"


def test_the_suite_argument_names_every_shipped_suite() -> None:
    """The `SUITE` item under "Commands" listed `default`, `quick` and `full` of the six suites in `benchmarks/`."""
    text = (ROOT / "docs" / "benchmarking.md").read_text("utf-8")
    item = text[text.index("- `SUITE` is a name in `benchmarks/`") :].split("\n- ", 1)[0]
    named = set(re.findall(r"`([a-z0-9-]+)`", item))
    shipped = {path.stem for path in (ROOT / "benchmarks").glob("*.toml")}
    assert shipped <= named, f"docs/benchmarking.md, Commands: SUITE does not name {sorted(shipped - named)}"
