"""The ``albot1`` entry point: assembles the command groups and turns the
project's known errors into one line on stderr with a non-zero exit.

Each command module imports only typer at module level; heavy libraries are
imported inside the commands, so ``albot1 --help`` is instant.
"""

from __future__ import annotations

import importlib
import sys

import typer

from albot1.errors import Albot1Error

app = typer.Typer(
    name="albot1",
    help="Albot1 perceptual mapping vs SLAM baselines on 2D laser datasets.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

#: (module, attribute, group name or None to add its commands at top level)
_COMMANDS: tuple[tuple[str, str, str | None], ...] = (
    ("albot1.cli.datasets", "app", "datasets"),
    ("albot1.cli.convert", "register", None),
    ("albot1.cli.run", "register", None),
    ("albot1.cli.methods", "register", None),
    ("albot1.cli.evaluate", "register", None),
    ("albot1.cli.bench", "register", None),
)

for _module_name, _attr, _group in _COMMANDS:
    _module = importlib.import_module(_module_name)
    if _group is None:
        getattr(_module, _attr)(app)
    else:
        app.add_typer(getattr(_module, _attr), name=_group)


def main() -> None:
    """Console-script entry: known errors -> ``albot1: error: ...`` on stderr, exit 1.

    Typer's standalone mode already turns usage errors into a usage message
    with exit 2; only the project's own errors need translating here.
    """
    try:
        app()
    except Albot1Error as exc:
        typer.echo(f"albot1: error: {exc}", err=True)
        sys.exit(1)
