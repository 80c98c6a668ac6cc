"""``albot1 bench [SUITE]`` and ``albot1 report RESULTS_DIR``: the benchmark grid and its report."""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from albot1.cli.interrupt import Interrupts, noting_interrupts, terminating_as_interrupt
from albot1.cli.progress import FigureBar, enabled
from albot1.runs.output import writable_folder
from albot1.settings import RESULTS_ROOT, get_settings

if TYPE_CHECKING:  # the bench's modules are imported when the command runs, not with the CLI
    from albot1.bench.grid import CellOutcome
    from albot1.bench.runner import GridObserver


class _HeedingCtrlC:
    """The grid's view, and at each cell's end a Ctrl-C whose KeyboardInterrupt went astray stops the runner.

    The runner stops on a KeyboardInterrupt raised where it waits; one that a finalizer dropped never reaches
    it, and it went on starting the grid's other cells (their lines hidden, the Ctrl-C honoured at the end).
    """

    def __init__(self, view: GridObserver, ctrl_c: Interrupts) -> None:
        self.view, self.ctrl_c = view, ctrl_c

    def started(self, total: int, cached: int) -> None:
        self.view.started(total, cached)

    def finished(self, outcome: CellOutcome) -> None:
        self.view.finished(outcome)
        self.ctrl_c.heed()


def register(app: typer.Typer) -> None:
    app.command("bench")(bench)
    app.command("report")(report)


def bench(
    suite: Annotated[
        str, typer.Argument(help="a suite name in benchmarks/ (default, quick, full) or a .toml path")
    ] = "default",
    jobs: Annotated[int, typer.Option("-j", "--jobs", help="cells run in parallel")] = 2,
    executor: Annotated[str, typer.Option(help="local | dask | dask://HOST:PORT")] = "local",
    scheduler: Annotated[
        str | None,
        typer.Option(help="HOST:PORT (or tcp://HOST:PORT) of a running Dask scheduler: --executor dask://HOST:PORT"),
    ] = None,
    results: Annotated[Path, typer.Option(help="results root; cells go to RESULTS/<suite>/runs/<key>")] = RESULTS_ROOT,
    data_dir: Annotated[Path | None, typer.Option(help="dataset folder (default: $ALBOT1_DATA_DIR)")] = None,
    progress: Annotated[bool, typer.Option(help="show the progress bar")] = True,
    dry_run: Annotated[bool, typer.Option("--dry-run", help="print the planned cells per dataset and stop")] = False,
    retry_failed: Annotated[
        bool,
        typer.Option(
            "--retry-failed", help="also run again the allowed failures (allow_failure) recorded by an earlier run"
        ),
    ] = False,
) -> None:
    """Run a benchmark suite: every dataset x method x degradation x seed cell, each in its own
    process under the suite's time and memory limits.

    Completed cells are kept and skipped on the next run; failed cells are recorded with their
    reason and retried, except a method's own error in a cell whose suite entry says
    `allow_failure` (the same key is the same code, config, data and seed: it would fail the
    same way; `--retry-failed` runs those again too). Then build the report with
    `albot1 report results/SUITE`. The exit status is 1 when any cell failed (after the whole
    grid ran and the summary was printed; not for a method's own failure in a cell whose suite
    entry says `allow_failure`), when the suite has no cell to run, and when the runner had to
    stop early (the results folder is full or read-only, or the cell process pool was killed:
    it starts no further cell, and running the same command again resumes).

    Datasets are named as in `albot1 run`: NAME, NAME[:N] (first N scans), NAME?key=value
    (loader options), or a path; a suite entry naming none of these is an error unless it
    says `optional = true`.

    Examples:\n
      albot1 bench                       # the default suite, 2 cells at a time\n
      albot1 bench quick -j 1\n
      albot1 bench default --executor dask -j 4\n
      albot1 bench benchmarks/full.toml --executor dask://scheduler:8786\n
      albot1 bench full --scheduler scheduler:8786     # the same
    """
    # The bench and report layers are imported by the command, not by this module: see albot1.cli.app.
    from tqdm import tqdm

    from albot1.bench.executors import check_jobs, parse_executor, scheduler_executor
    from albot1.bench.plan import plan_suite
    from albot1.bench.progress import TqdmProgress, plan_table, summary_table
    from albot1.bench.runner import run_suite
    from albot1.bench.suite import find_suite, load_suite
    from albot1.report.preview import render_preview

    if scheduler is not None:
        executor = scheduler_executor(scheduler, executor)
    if dry_run:
        # What the run would refuse, the dry run refuses too: `-j 0` or `--executor ray` passed it with exit 0.
        check_jobs(jobs)
        parse_executor(executor)
        with contextlib.redirect_stdout(sys.stderr):  # what a method's module prints as it is imported (below)
            plan = plan_suite(load_suite(find_suite(suite)), get_settings(data_dir=data_dir))
        typer.echo(plan_table(plan))
        return
    # The bar (cells done of the total, with an ETA) only on a terminal: piped output and CI logs stay clean.
    # After Ctrl-C a cell may still end, killed by it (its forkserver died: "executor error"); that is the interrupt,
    # not a failure to report above the "interrupted" line.
    ctrl_c = Interrupts()
    view = TqdmProgress(
        lambda line: None if ctrl_c.received else tqdm.write(line, file=sys.stderr),
        disable=not (progress and enabled()),
    )
    try:
        # What a method's module prints as the planner imports it (a plugin's banner) goes to stderr: stdout is
        # the tables (the cells' output goes to their logs; the forkserver's preload sends it to stderr too).
        with (
            noting_interrupts(ctrl_c),
            terminating_as_interrupt(ctrl_c),
            contextlib.redirect_stdout(sys.stderr),
        ):
            plan, summary, store = run_suite(
                suite,
                results=results,
                jobs=jobs,
                executor=executor,
                observer=_HeedingCtrlC(view, ctrl_c),
                settings=get_settings(data_dir=data_dir),
                preview=render_preview,
                retry_failed=retry_failed,
            )
        interrupted = ctrl_c.received  # a KeyboardInterrupt lost in a finalizer still ends the command as Ctrl-C
    except KeyboardInterrupt:
        interrupted = True
    finally:
        view.close()
    if interrupted:
        # The cells got the same Ctrl-C (or the SIGINT a SIGTERM was handed on as) and stopped; the store is
        # consistent. The exit status is the shell's for the signal that stopped it.
        typer.echo(ctrl_c.line("completed cells are kept, run the same command again to resume"), err=True)
        raise typer.Exit(ctrl_c.status())
    for skipped in plan.skipped_datasets:
        typer.echo(
            f"skipped dataset {skipped.name}: {skipped.reason}"
            + (f" (get it with `{skipped.hint}`)" if skipped.hint else ""),
            err=True,
        )
    for skipped in plan.skipped_methods:
        typer.echo(f"skipped method {skipped.name}: {skipped.reason}", err=True)
    for damage in summary.damaged:
        typer.echo(f"damaged run folder, computed again: {damage}", err=True)
    typer.echo(summary_table(summary))
    typer.echo(f"results: {store.root}  (report: albot1 report {store.root})")
    failed = summary.counts["failed"]
    if not plan.cells:
        typer.echo(f"suite {plan.suite}: no cell to run (every dataset or method it selects was skipped)", err=True)
        raise typer.Exit(1)
    if summary.halted is not None:
        left = f"; {len(summary.not_started)} cells not started" if summary.not_started else ""
        typer.echo(
            f"halted: {summary.halted}{left}; completed cells are kept, run the same command again to resume",
            err=True,
        )
    blocking = len(summary.blocking_failures)
    if failed:
        # The whole grid ran and the summary is printed; the exit status tells scripts (make, CI) it is not clean.
        allowed = failed - blocking
        typer.echo(
            f"{failed} of {len(summary.outcomes)} cells failed (reasons above and in the report)"
            + (f"; {allowed} of them by methods the suite allows to fail (allow_failure)" if allowed else ""),
            err=True,
        )
    if blocking or summary.halted is not None:
        raise typer.Exit(1)


def report(
    results_dir: Annotated[Path, typer.Argument(help="a results folder written by `albot1 bench` (results/SUITE)")],
    out: Annotated[Path | None, typer.Option(help="report folder (default: reports/<suite>)")] = None,
    plots: Annotated[bool, typer.Option(help="render the plots (tables only with --no-plots)")] = True,
    map_style: Annotated[
        str, typer.Option(help="point maps drawn as an occupancy grid (grid) or as their points (points)")
    ] = "grid",
    jobs: Annotated[int, typer.Option("--jobs", "-j", min=1, help="processes drawing the plots")] = 1,
    columns: Annotated[
        str | None,
        typer.Option(
            help="KEY,KEY,...: the number columns of the accuracy and cost tables, in this order (method, "
            "degradation, seeds and status always show; cells.csv keeps every column)"
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="build everything again, trusting no stamp of an earlier build")
    ] = False,
) -> None:
    """Build tables (Markdown, CSV, LaTeX), plots (PNG and SVG), README.md and index.html from a results folder.

    index.html is the whole report on one page (sortable tables whose columns can be hidden, every
    plot), with relative links only: open it from the report folder in any browser, no network needed.

    --columns narrows the tables (Markdown, CSV, LaTeX and HTML) to the named columns; a wrong key
    is an error that lists the valid ones (docs/benchmarking.md, "Tables").

    Incremental: when nothing the report is built from changed since its last build (the store's
    files by content, the code, the options) and its files are untouched, nothing is rebuilt;
    otherwise only the figures whose own runs changed are drawn again. --force rebuilds it all
    (same bytes).

    Examples:\n
      albot1 report results/default -j 2   # -> reports/default/index.html\n
      albot1 report results/quick --out /tmp/quick-report --map-style points\n
      albot1 report results/quick --columns ate_rmse_m,loop_gap_m,total_s
    """
    # Imported by the command, not by this module: see albot1.cli.app.
    from albot1.report import rebuild
    from albot1.report.folders import default_out

    if map_style not in ("grid", "points"):
        raise typer.BadParameter(f"--map-style {map_style!r}: expected grid or points")
    target = out if out is not None else default_out(results_dir)
    if not force:  # the check reads the stamp and the store's files, and imports nothing heavy
        page = rebuild.current_report(results_dir, target, plots=plots, map_style=map_style, columns=columns)
        if page is not None:
            typer.echo(f"report: {page} (up to date: nothing it is built from changed)")
            return
    from albot1.bench.store import ResultsStore

    rebuild.column_selection(columns)  # a wrong key: say so first
    ResultsStore(results_dir).read_plan()  # not a results folder: say so before making the report folder
    writable_folder(target, "--out")
    bar = FigureBar()
    try:
        index = rebuild.report(
            results_dir,
            out,
            plots=plots,
            map_style=map_style,
            columns=columns,
            jobs=jobs,
            progress=bar.update,
            force=force,
        )
    finally:
        bar.close()
    typer.echo(f"report: {index}")
