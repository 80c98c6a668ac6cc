"""``albot1 results-page``: the compact results page (docs/results.md) and the README's numbers, after a bench."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def register(app: typer.Typer) -> None:
    app.command("results-page")(results_page)


def results_page(
    default: Annotated[Path, typer.Argument(help="the default suite's results folder (standard benchmark)")],
    thesis: Annotated[
        Path | None, typer.Option(help="the thesis suite's results folder (verdicts at a glance)")
    ] = None,
    out: Annotated[Path, typer.Option(help="the page to write (its figures and record go to <dir>/results/)")] = Path(
        "docs/results.md"
    ),
    readme: Annotated[
        Path | None, typer.Option(help="a README whose results block (between the markers) is rewritten")
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="write everything again, trusting no stamp of an earlier run")
    ] = False,
) -> None:
    """Write docs/results.md, docs/results/*.svg and results.json from the stores `make bench` filled.

    Stamped with each store's suite, code version and commit; no date, so nothing new means no change.

    With --readme, the block between the results:begin and results:end markers is rewritten too.

    Incremental: when neither store, the code, the options nor the written files changed since the
    last run (stamp: <dir>/results/build.json), nothing is read or drawn again.

    Example:\n
      albot1 results-page results/default --thesis results/thesis \\
          --readme README.md
    """
    # Imported by the command, not by this module: see albot1.cli.app.
    from albot1.report import rebuild

    if thesis is not None and not (thesis / "grid.json").is_file():
        # Not an error: `make bench SUITE=default` names results/thesis before the thesis suite ever ran. But a
        # mistyped folder must not drop the verdicts with only a note deep in the page.
        typer.echo(
            f"results-page: NOTICE: --thesis {thesis.as_posix()} is not a results folder (no grid.json): the page "
            "shows no verdicts and no column of the methods only the thesis suite runs",
            err=True,
        )

    if not force:  # the check reads the stamp and the stores' files, and imports nothing heavy
        current = rebuild.current_results_page(default, thesis, out, readme)
        if current is not None:
            for path in current:
                typer.echo(f"results-page: {path} (up to date)")
            return
    from albot1.bench.store import ResultsStore

    ResultsStore(default).read_plan()  # not a results folder: say so in one line
    for path in rebuild.results_page(default, thesis, out, readme):
        typer.echo(f"results-page: {path}")
