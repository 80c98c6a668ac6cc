"""The ``albot1`` entry point: assembles the command groups and turns the
project's known errors into one line on stderr with a non-zero exit.

Every command module is imported here, as Typer needs each command's
parameters and help to build ``albot1 --help``; so a command module's top
imports only Typer, the standard library and the cheap base modules
(``settings``, ``errors``, ``runs.output``, ``cli.progress``), and each command
function imports the layers that do its work (data, runs, bench, report and,
below them, numpy and pydantic) when it runs. ``albot1 --help`` then costs
about Typer's import, not the whole package's;
``tests/unit/cli/test_cli_imports.py`` keeps it so.
"""

from __future__ import annotations

import importlib
import sys
from typing import Annotated

import typer

from albot1 import __version__
from albot1.cli.helptext import install as install_help
from albot1.errors import Albot1Error

HELP = """Albot1 perceptual mapping vs SLAM baselines on 2D laser datasets.

Every command names a dataset the same way (run, evaluate, convert, datasets info, suites):\n
NAME: a registered dataset (`albot1 datasets list`) or a synthetic world;\n
NAME[:N]: its first N scans (NAME[:N:S] every S-th of them, NAME[::S]);\n
NAME?key=value: loader options joined by &, e.g. intel-corrected?odometry=laser-pose;
on any dataset odometry=reference (perfect odometry) and views=D_M:A_DEG;\n
PATH: a log file (CARMEN, ROS1/ROS2 bag, Albot1 log; the format is sniffed).\n
Quote references in a shell: albot1 run odometry 'aces[:2500]'.
"""

app = typer.Typer(
    name="albot1",
    help=HELP,
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _version(value: bool) -> None:
    if value:
        from albot1.versions import code_version, commit_label, git_commit  # only for --version

        typer.echo(f"albot1 {__version__} (code {code_version()}, {commit_label(git_commit())})")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            callback=_version,
            is_eager=True,
            help="print the version, the code digest and the git commit, exit",
        ),
    ] = False,
) -> None:
    """The options of ``albot1`` itself (the commands are added below)."""


#: (module, attribute, group name or None to add its commands at top level)
_COMMANDS: tuple[tuple[str, str, str | None], ...] = (
    ("albot1.cli.datasets", "app", "datasets"),
    ("albot1.cli.convert", "register", None),
    ("albot1.cli.run", "register", None),
    ("albot1.cli.methods", "register", None),
    ("albot1.cli.evaluate", "register", None),
    ("albot1.cli.runs", "register", None),
    ("albot1.cli.bench", "register", None),
    ("albot1.cli.results", "register", None),
    ("albot1.cli.warm_up", "register", None),
)

for _module_name, _attr, _group in _COMMANDS:
    _module = importlib.import_module(_module_name)
    if _group is None:
        getattr(_module, _attr)(app)
    else:
        app.add_typer(getattr(_module, _attr), name=_group)
install_help(app)


def main() -> None:
    """Console-script entry: known errors -> ``albot1: error: ...`` on stderr, exit 1.

    Typer's standalone mode already turns usage errors into a usage message
    with exit 2; the project's own errors, and the operating system's refusals
    that reach this far (a disk that fills up mid-command, a file whose
    permissions changed), are one line naming the path. Any other exception is
    a bug and keeps its traceback. Ctrl-C and SIGTERM are the console script's
    (:mod:`albot1.cli.entry`, which runs this): Typer turns Ctrl-C into a silent
    exit 130, and the console script says which stop it was.
    """
    try:
        app()
    except Albot1Error as exc:
        typer.echo(f"albot1: error: {exc}", err=True)
        sys.exit(1)
    except OSError as exc:
        typer.echo(f"albot1: error: {os_error_line(exc)}", err=True)
        sys.exit(1)


def os_error_line(exc: OSError) -> str:
    """``PATH: cannot read or write it: no space left on device`` -- one line for an OSError."""
    what = (exc.strerror or str(exc) or type(exc).__name__).lower()
    where = exc.filename if exc.filename is not None else "a file"
    if exc.filename2 is not None:
        where = f"{where} -> {exc.filename2}"
    return f"{where}: cannot read or write it: {what}"
