"""Every `albot1 ... --help` at 80 and 140 columns: within the width, prose not ragged, flags without a type."""

from __future__ import annotations

import click
import pytest
import typer
from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.cli.helptext import reflow

runner = CliRunner()


def _command_paths() -> list[list[str]]:
    paths: list[list[str]] = []

    def walk(command: click.Command, path: list[str]) -> None:
        paths.append(path)
        for name, sub in getattr(command, "commands", {}).items():
            walk(sub, [*path, name])

    walk(typer.main.get_command(app), [])
    return paths


COMMANDS = _command_paths()


def test_reflow_joins_prose_and_keeps_example_blocks() -> None:
    doc = """First line.

    A paragraph wrapped
    in the source
    at any width.

    Examples:\n
      albot1 run a b\n
      albot1 run c d \\
          --seed 1
    """
    assert reflow(doc) == (
        "First line.\n\n\nA paragraph wrapped in the source at any width.\n\nExamples:\n\n"
        "  albot1 run a b\n  albot1 run c d \\\n      --seed 1"
    )
    assert reflow(None) is None
    assert reflow("One line\n  wrapped.") == "One line wrapped."


def test_every_command_is_walked() -> None:
    names = {" ".join(path) for path in COMMANDS}
    assert {"", "run", "bench", "report", "methods", "evaluate", "convert", "runs", "datasets list"} <= names


@pytest.mark.parametrize("width", [80, 140])
@pytest.mark.parametrize("path", COMMANDS, ids=lambda p: " ".join(p) or "albot1")
def test_help_fits_the_width_is_not_ragged_and_flags_have_no_type(path: list[str], width: int) -> None:
    result = runner.invoke(app, [*path, "--help"], env={"COLUMNS": str(width)})
    assert result.exit_code == 0, result.output
    lines = [line.rstrip() for line in result.output.splitlines()]
    assert max(len(line) for line in lines) <= width
    assert "<bool>" not in result.output
    # The description (above the first panel): a prose line is broken only where the next word does not fit.
    description = lines[: next(i for i, line in enumerate(lines) if line.startswith("╭"))]
    for line, following in zip(description, description[1:]):
        prose = line.startswith(" ") and not line.startswith("   ")
        if prose and following.strip() and not following.startswith("   "):
            next_word = following.split()[0]
            assert len(line) + 1 + len(next_word) > width - 2, (line, following)
    # Every example line of the docstring is shown whole, on its own line.
    command = typer.main.get_command(app)
    for name in path:
        command = command.commands[name]  # type: ignore[attr-defined]
    for example in (reflow(command.help) or "").splitlines():
        if example[:1].isspace():
            assert f" {example}" in lines, example
