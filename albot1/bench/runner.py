"""Run a grid plan: skip completed cells, submit the rest, collect outcomes as they complete.

The runner holds no result in memory that is not already on disk: the plan
is written first, every cell writes its own folder, and the summary is
recomputed from the store. Killing the runner at any moment therefore loses
at most the cells that were in flight.

A failure that would repeat for every cell (the results folder is full or
read-only, the cell process pool was killed) halts the grid: the runner
starts no further cell, lets the running ones end, and says how many it did
not start; a later run resumes where it stopped.
"""

from __future__ import annotations

import concurrent.futures as cf
import time
import traceback
import uuid
from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path
from typing import Protocol

from albot1.bench.cells import renderer_target
from albot1.bench.errors import BenchError
from albot1.bench.executors import check_jobs, executor_failure, executor_lost, open_executor, parse_executor
from albot1.bench.grid import Cell, CellOutcome, GridPlan
from albot1.bench.job import results_path, run_cell_job
from albot1.bench.limits import CellNotStarted, allow_launching, start_forkserver, stop_launching
from albot1.bench.order import longest_first, past_costs
from albot1.bench.plan import plan_suite
from albot1.bench.store import LOG, UNREADABLE_FAILURE, ResultsStore
from albot1.bench.suite import find_suite, load_suite
from albot1.methods.registry import method_registry
from albot1.runs.folder import PreviewRenderer
from albot1.runs.output import writable_folder
from albot1.settings import Settings, get_settings


class GridObserver(Protocol):
    """What the runner reports while it works (the CLI attaches a progress bar)."""

    def started(self, total: int, cached: int) -> None: ...

    def finished(self, outcome: CellOutcome) -> None: ...


@dataclass
class GridSummary:
    """Counts and outcomes of one runner invocation.

    ``halted``: why the runner stopped starting cells (None: it ran the whole
    grid); ``not_started``: the cells it then left for a later run;
    ``damaged``: for each run folder marked DONE that was no readable run of
    its cell (:meth:`ResultsStore.damage`), what was wrong; those cells ran again.
    """

    outcomes: list[CellOutcome] = field(default_factory=list)
    wall_s: float = 0.0
    halted: str | None = None
    not_started: list[Cell] = field(default_factory=list)
    damaged: list[str] = field(default_factory=list)

    @property
    def counts(self) -> Counter[str]:
        return Counter(o.status for o in self.outcomes)

    @property
    def failures(self) -> list[CellOutcome]:
        return [o for o in self.outcomes if o.status == "failed"]

    @property
    def blocking_failures(self) -> list[CellOutcome]:
        """The failures that make the bench exit non-zero: all but those the suite allows."""
        return [o for o in self.failures if not o.allowed]


#: Grids of this process that a failure halted (see :func:`_unless_halted`).
_HALTED_GRIDS: set[str] = set()


def _unless_halted(job: Callable[[Cell, str], CellOutcome], grid_id: str, cell: Cell, root: str) -> CellOutcome | None:
    """Run ``job`` unless grid ``grid_id`` was halted (None: not started); a halting outcome halts it.

    The flag is set by the thread that met the failure, before it takes the
    next cell from the pool's queue: cancelling the queued futures from the
    runner's thread alone would come too late for that next cell. (On Dask
    workers, other processes, the runner's cancellation is what stops cells.)
    """
    if grid_id in _HALTED_GRIDS:
        return None
    try:
        outcome = job(cell, root)
    except CellNotStarted:  # the runner stops (Ctrl-C): this cell is one it never reached
        return None
    if outcome.halts_grid:
        _HALTED_GRIDS.add(grid_id)
    return outcome


def _unique(cells: list[Cell]) -> list[Cell]:
    """One cell per key: two labels resolving to the same inputs share one run folder."""
    seen: dict[str, Cell] = {}
    for cell in cells:
        seen.setdefault(cell.key, cell)
    return list(seen.values())


def _config_failure(store: ResultsStore, cell: Cell, reason: str) -> CellOutcome:
    """Record a cell whose config does not resolve (it never starts); a full disk halts the grid."""
    try:
        store.prepare(cell)
    except OSError:
        pass  # record_failure below says whether anything could be written
    problem = store.record_failure(cell, reason, "config")
    if problem is None:
        return CellOutcome.of(cell, "failed", 0.0, reason, "config")
    return CellOutcome.of(cell, "failed", 0.0, f"{reason} [not recorded: {problem}]", "storage", halts_grid=True)


def run_grid(
    plan: GridPlan,
    store: ResultsStore,
    executor: cf.Executor,
    observer: GridObserver | None = None,
    job: Callable[[Cell, str], CellOutcome] = run_cell_job,
    *,
    keep_allowed_failures: bool = False,
) -> GridSummary:
    """Run every incomplete cell of ``plan`` on ``executor``; failures are recorded, never raised.

    An outcome that halts the grid (:attr:`CellOutcome.halts_grid`) cancels
    every cell not yet started; they are listed in ``summary.not_started``.
    ``keep_allowed_failures``: a cell whose recorded failure :func:`kept_failure`
    keeps is reported from its record instead of being run again.
    """
    start = time.monotonic()
    summary = GridSummary()
    cells = _unique(plan.cells)
    pending: list[Cell] = []
    for cell in cells:
        if summary.halted is not None:
            summary.not_started.append(cell)
        elif cell.key in plan.config_failures:
            outcome = _config_failure(store, cell, plan.config_failures[cell.key])
            summary.outcomes.append(outcome)
            if outcome.halts_grid:
                summary.halted = outcome.reason
        elif (damage := store.damage(cell.key)) is None and store.is_complete(cell.key):
            summary.outcomes.append(CellOutcome.of(cell, "cached"))
        elif keep_allowed_failures and (kept := kept_failure(store, cell)) is not None:
            summary.outcomes.append(kept)
        else:
            if damage is not None:  # said, not kept as a result nor dropped in silence: the cell runs again
                summary.damaged.append(damage)
            pending.append(cell)
    if summary.halted is not None:
        summary.not_started += pending
        pending = []
    elif len(pending) > 1:  # longest expected first, so that no long cell runs alone at the end (albot1.bench.order)
        pending = longest_first(pending, past_costs([store.root]))
    if observer is not None:
        observer.started(len(cells), len(cells) - len(pending) - len(summary.failures) - len(summary.not_started))
        for outcome in summary.outcomes:
            if outcome.status == "failed":
                observer.finished(outcome)
    root = results_path(store.root)
    grid_id = uuid.uuid4().hex
    futures = {executor.submit(_unless_halted, job, grid_id, cell, root): cell for cell in pending}
    # One waiter for the whole grid (``as_completed``): ``cf.wait`` in a loop
    # registers a waiter on every pending future per completion, which is
    # quadratic in the cells (16 s of bookkeeping for 5,000 trivial jobs).
    cancelled: set[cf.Future[CellOutcome | None]] = set()
    started_at = time.time()
    allow_launching()
    try:
        for future in _completed(futures, cancelled):
            halt: str | None = None
            if future.cancelled():  # not by the runner: the executor lost it
                halt = executor_lost(executor) or "the executor cancelled the cell (its Dask scheduler restarted?)"
                ended = _lost(futures[future], store, halt, started_at)
            else:
                ended = _outcome(future, futures[future], store, executor)
            if ended is None:
                summary.not_started.append(futures[future])
            else:
                summary.outcomes.append(ended)
                if observer is not None:
                    observer.finished(ended)
                if ended.halts_grid:
                    halt = halt or ended.reason
            if halt is not None and summary.halted is None:
                summary.halted = halt
                cancelled.update([f for f in futures if not f.done() and f.cancel()])
                summary.not_started += [futures[f] for f in futures if f in cancelled]
    except BaseException:  # Ctrl-C, SIGTERM: no cell thread may start another cell (limits.stop_launching)
        stop_launching()
        raise
    finally:
        for future in futures:
            future.cancel()
        _HALTED_GRIDS.discard(grid_id)
    order = {cell.key: index for index, cell in enumerate(cells)}
    summary.not_started.sort(key=lambda cell: order[cell.key])
    summary.wall_s = time.monotonic() - start
    return summary


def _completed(
    futures: Iterable[cf.Future[CellOutcome | None]], cancelled: set[cf.Future[CellOutcome | None]]
) -> Iterator[cf.Future[CellOutcome | None]]:
    """``futures`` as they complete (``cf.as_completed``), leaving out those in ``cancelled`` (the caller adds to it).

    After a halt the runner cancels the cells not yet started and waits only
    for the others. A Dask client's ``concurrent.futures`` future stays
    *pending* while its task runs, so the runner's ``cancel`` can succeed on a
    running cell; when that task then ends, ``distributed`` sets its result on
    the cancelled future, which raises ``InvalidStateError`` in its callback
    and leaves the future cancelled but never notified: ``as_completed`` would
    wait for it forever (seen once in CI: a grid halted by a read-only worker
    hung until the test's 300 s timeout). So the waiting restarts over the
    futures not cancelled (at most once per halt).
    """
    remaining = set(futures)
    while remaining:
        remaining -= cancelled
        before = len(cancelled)
        for future in cf.as_completed(remaining):
            remaining.discard(future)
            yield future
            if len(cancelled) != before:  # a halt cancelled cells: wait again, without them
                break


def kept_failure(store: ResultsStore, cell: Cell) -> CellOutcome | None:
    """The recorded failure of ``cell`` when running it again would only repeat it, else None.

    Kept: the method's own error (kind ``exception``, e.g. MRPT's detected
    divergence) in a cell whose suite entry allows it to fail. The cell's key
    names its code version, config, data and seed, so the same key is the
    same computation; without this, every `make bench` spent minutes
    re-running the same divergences. Retried as before: time and memory
    limits and crashes (they depend on the machine's load), every failure
    not allowed by the suite, and an unreadable record.
    """
    if not cell.allow_failure:
        return None
    recorded = store.failure(cell.key, strict=False)
    if recorded is None or recorded.kind != "exception" or recorded.reason == UNREADABLE_FAILURE:
        return None
    # No time spent in this run (its attempt's time stays in FAILED.json), as for a complete cell kept.
    outcome = CellOutcome.of(cell, "failed", 0.0, recorded.reason, "exception")
    return replace(outcome, kept=True)


def _outcome(
    future: cf.Future[CellOutcome | None], cell: Cell, store: ResultsStore, executor: cf.Executor
) -> CellOutcome | None:
    """The job's outcome, or a recorded executor failure when the executor lost the job.

    A failure the job could not record itself (a Dask worker that cannot
    write the results folder the runner can) is recorded here, so that
    every failed cell has its FAILED.json wherever it ran.
    """
    try:
        outcome = future.result()
    except Exception as exc:  # the executor lost the job (worker died, scheduler lost, unpicklable, ...)
        reason, halts = executor_failure(exc, executor)
        problem = store.record_failure(
            cell, reason, "executor", traceback_text="".join(traceback.format_exception(exc))
        )
        if problem is not None:
            return CellOutcome.of(
                cell, "failed", 0.0, f"{reason} [not recorded: {problem}]", "storage", halts_grid=True
            )
        return CellOutcome.of(cell, "failed", 0.0, reason, "executor", halts_grid=halts)
    if outcome is not None and outcome.status == "failed" and outcome.kind is not None:
        reason = _recorded(outcome.reason) or ""
        if (
            store.failure(outcome.key, strict=False) is None
            and store.record_failure(cell, reason, outcome.kind, elapsed_s=outcome.elapsed_s) is None
        ):
            outcome = replace(outcome, reason=reason)
    return outcome


def _recorded(reason: str | None) -> str | None:
    """``reason`` without the job's note that it could not record it (the runner just did)."""
    if reason is None or " [not recorded: " not in reason:
        return reason
    return reason[: reason.index(" [not recorded: ")]


def _lost(cell: Cell, store: ResultsStore, why: str, started_at: float) -> CellOutcome | None:
    """A cell whose job the executor dropped: recorded as failed when it had started in this run, else None.

    Started: its attempt's log (rewritten by every attempt) is newer than the grid's submission.
    """
    try:
        started = (store.run_dir(cell.key) / LOG).stat().st_mtime >= started_at - 1.0
    except OSError:
        started = False
    if not started or store.is_complete(cell.key):
        return CellOutcome.of(cell, "done") if store.is_complete(cell.key) else None
    reason = f"{why}; the cell was running"
    problem = store.record_failure(cell, reason, "executor")
    if problem is not None:
        reason = f"{reason} [not recorded: {problem}]"
    return CellOutcome.of(cell, "failed", 0.0, reason, "executor", halts_grid=True)


def bench_results_root(results: Path, suite_name: str) -> Path:
    """``results/<suite>``: the folder `albot1 report` reads.

    A suite's name is a plain folder name (the suite model checks it); this
    checks again, so that no name ever places a results folder outside ``results``.
    """
    root = results / suite_name
    if root.resolve().parent != results.resolve():
        raise BenchError(
            f"suite name {suite_name!r} would put its results at {root.resolve()}, outside {results.resolve()}; "
            "expected a plain folder name (letters, digits, '_', '.', '-', not starting with '.')"
        )
    return root


def run_suite(
    suite_ref: str,
    *,
    results: Path,
    jobs: int = 2,
    executor: str = "local",
    observer: GridObserver | None = None,
    settings: Settings | None = None,
    dask_processes: bool = True,
    preview: PreviewRenderer | None = None,
    retry_failed: bool = False,
) -> tuple[GridPlan, GridSummary, ResultsStore]:
    """Load, plan and run a suite into ``results/<suite>``: what `albot1 bench` does.

    ``retry_failed``: run again the allowed failures :func:`kept_failure` would keep.

    ``preview`` draws each run's ``preview.png`` (the CLI passes
    ``albot1.report.preview.render_preview``); it must be a module-level function,
    as the cell processes import it by name.
    """
    kind, _ = parse_executor(executor)  # a typo fails before any planning work
    check_jobs(jobs)
    job = partial(run_cell_job, preview=renderer_target(preview) if preview is not None else None)
    suite_file = find_suite(suite_ref)
    suite = load_suite(suite_file)
    if kind == "local":
        # Only registered names: the server warns about any other as a typo in ALBOT1_PRELOAD_METHODS, a variable
        # the user never set, beside the planner's own "unknown method" error (which follows).
        registered = method_registry()
        start_forkserver(
            None
            if suite.registered_methods
            else {m.name for m in suite.methods if m.trajectories is None and m.name in registered}
        )
    plan = plan_suite(suite, settings or get_settings())
    writable_folder(results, "--results")  # after the suite and its plan: a bad suite makes no folder
    store = ResultsStore(bench_results_root(results, suite.name))
    store.lock()
    try:
        store.write_plan(plan, suite_file)
        with open_executor(executor, jobs, dask_processes=dask_processes) as pool:
            summary = run_grid(plan, store, pool, observer, job=job, keep_allowed_failures=not retry_failed)
    finally:
        store.unlock()
    return plan, summary, store
