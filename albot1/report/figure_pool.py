"""A report's figures, drawn in worker processes while the report writes its tables.

Drawing is most of a report's CPU time (matplotlib's layout and two file
formats per figure), and each dataset's figures depend on its records alone,
so with ``jobs`` > 1 they are drawn in that many worker processes. The
figures are the same files either way; what this module decides is *when*
they are drawn, which sets a report's wall time on a shared machine
(`make bench` builds three reports and the results page at once on two
cores):

* **Started first.** :func:`start_plots` hands the workers their work as
  soon as the store is read, before the paired bootstraps, the tables and
  the pages (tens of seconds of one core for the default suite), which the
  report's own process then writes while the workers draw; the report waits
  for the figures (:meth:`PendingPlots.result`) only when its index needs
  their files. It used to draw them after all of that, so its single-core
  head and tail added to its time instead of overlapping it.
* **Longest first.** The datasets are handed out in the order of an
  estimate of their cost (:func:`drawing_cost`: the size of the run files
  their figures read), so the cheap ones fill the end and no worker draws
  a long maps figure alone while the other idles.
* **What needs the tables, last.** The robustness figures read the
  aggregated metrics table, which takes seconds to make: they are separate
  tasks, handed out once the table exists, after every dataset's other
  figures; so is the cross-dataset runtime figure (the cost table).

A dataset's figure list keeps its fixed order whichever task drew which
(:data:`KINDS`), and the figure cache (:mod:`albot1.report.figure_cache`)
stores a dataset only once all its figures are on disk. Without worker
processes (``jobs`` 1) nothing is drawn before :meth:`PendingPlots.result`:
the report's own process draws everything there, in suite order.
"""

from __future__ import annotations

import multiprocessing
import threading
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING

from albot1.errors import Albot1Error
from albot1.report.collect import CellRecord
from albot1.report.cost_plots import plot_runtime, plot_scan_time
from albot1.report.figure_cache import FigureCache, inputs_digest
from albot1.report.map_plots import MapStyle, plot_maps
from albot1.report.plots import method_colors, representative, slug
from albot1.report.relation_plots import plot_relation_boxes
from albot1.report.robustness_plots import plot_robustness
from albot1.report.rpe_plots import plot_rpe_boxes
from albot1.report.tables import Aggregates
from albot1.report.trajectory_plots import plot_ape_map, plot_error_vs_distance, plot_trajectories

#: The folder of a report's figures, in its output folder.
PLOTS_DIR = "plots"

if TYPE_CHECKING:
    import pandas as pd  # annotations only: importing the report does not import pandas

#: Told ``(datasets whose figures are drawn, datasets to draw)`` while the report draws its figures.
PlotProgress = Callable[[int, int], None]
#: The metrics whose robustness (value per degradation) is plotted: column, axis label, file suffix.
ROBUSTNESS = (
    ("ate_rmse_m", "ATE RMSE (m)", "robustness-ate"),
    ("drift_10m_m", "RPE per 10 m, translation (m)", "robustness-drift"),
    ("loop_gap_m", "loop gap (m)", "robustness-loop-gap"),
)
#: A dataset's figures in the order its index lists them: the run figures, the robustness ones, the scan time.
KINDS = (
    "trajectories",
    "ape",
    "error-distance",
    "rpe-boxes",
    "relation-boxes",
    "maps",
    *[kind for _, _, kind in ROBUSTNESS],
    "scan-time",
)
#: Files of a run that its dataset's figures read, whose sizes estimate the drawing's cost.
_RUN_FILES = ("trajectory.tum", "reference.tum")


def _run_figures(
    dataset: str, recs: list[CellRecord], plots_dir: Path, colors: dict[str, str], map_style: MapStyle
) -> dict[str, Path | None]:
    """The figures of one dataset drawn from its run folders, by kind (a module-level function: workers run it)."""
    stem = slug(dataset)

    def at(kind: str) -> Path:
        return plots_dir / f"{stem}-{kind}.png"

    return {
        "trajectories": plot_trajectories(recs, dataset, at("trajectories"), colors),
        "ape": plot_ape_map(recs, dataset, at("ape"), colors),
        "error-distance": plot_error_vs_distance(recs, dataset, at("error-distance"), colors),
        "rpe-boxes": plot_rpe_boxes(recs, dataset, at("rpe-boxes"), colors),
        "relation-boxes": plot_relation_boxes(recs, dataset, at("relation-boxes"), colors),
        "maps": plot_maps(recs, dataset, at("maps"), colors, style=map_style),
        "scan-time": plot_scan_time(recs, dataset, at("scan-time"), colors),
    }


def _robustness_figures(
    dataset: str, metrics: pd.DataFrame, plots_dir: Path, colors: dict[str, str]
) -> dict[str, Path | None]:
    """The robustness figures of one dataset, drawn from the aggregated metrics table, by kind."""
    stem = slug(dataset)
    return {
        kind: plot_robustness(metrics, dataset, column, label, plots_dir / f"{stem}-{kind}.png", colors)
        for column, label, kind in ROBUSTNESS
    }


def _ordered(drawn: dict[str, Path | None]) -> list[Path]:
    """A dataset's figures in :data:`KINDS` order, those not drawn (no data for them) left out."""
    return [f for f in (drawn.get(kind) for kind in KINDS) if f is not None]


def _dataset_plots(
    dataset: str,
    recs: list[CellRecord],
    metrics: pd.DataFrame,
    plots_dir: Path,
    colors: dict[str, str],
    map_style: MapStyle,
) -> list[Path]:
    """Every figure of one dataset, in order (the report's own process, ``jobs`` 1)."""
    return _ordered(
        {
            **_run_figures(dataset, recs, plots_dir, colors, map_style),
            **_robustness_figures(dataset, metrics, plots_dir, colors),
        }
    )


def _colors_of(records: list[CellRecord], colors: dict[str, str]) -> dict[str, str]:
    """The colours of the methods in ``records`` (what a dataset's figures draw them in)."""
    labels = {r.cell.method_label for r in records}
    return {label: color for label, color in colors.items() if label in labels}


def drawing_cost(records: list[CellRecord]) -> int:
    """An estimate of the cost of drawing a dataset's figures: bytes of the run files they read.

    The trajectories of every completed run (error and time figures), and the map of each method's pictured
    run (the maps figure, the dearest: a whole-log map is megabytes). Only an order: a wrong guess costs
    balance, never a figure.
    """
    done = [r for r in records if r.status == "done"]
    size = 0
    for rec in done:
        for name in _RUN_FILES:
            size += _size(rec.run_dir / name)
    for rec in representative(done).values():
        if rec.result is not None and rec.result.map_file:
            size += _size(rec.run_dir / rec.result.map_file)
    return size


def read_pictured(records: list[CellRecord]) -> None:
    """Read the run folder and the map of each pictured run of one dataset, into its record.

    The report's own process reads them anyway (the paired comparisons read every run, the interactive view
    the pictured maps), so reading them before a dataset is handed to a worker costs nothing more, and the
    records sent to the worker carry them (numpy arrays pickle at memory speed; re-reading a run's text files
    and decoding a line map's GeoJSON was ~10 CPU-s of the default report's workers). A run that cannot be
    read is left to the figure that needs it, which fails as it did (the same error, from the worker).
    """
    for rec in representative(r for r in records if r.status == "done").values():
        try:
            rec.stored_run()
            rec.map_geometry()  # reads the map too (stored_map), as the maps figure does
        except Albot1Error:
            continue


def _size(path: Path) -> int:
    try:
        return path.stat().st_size
    except OSError:
        return 0


class PendingPlots:
    """The figures of a report being drawn: :meth:`result` waits for them; use as a context manager.

    Leaving the context without :meth:`result` (the report failed meanwhile) cancels what was not started
    and stops the workers.
    """

    def __init__(
        self,
        records: list[CellRecord],
        out: Path,
        colors: dict[str, str] | None,
        *,
        map_style: MapStyle,
        jobs: int,
        progress: PlotProgress | None,
        aggregates: Aggregates | None,
    ) -> None:
        self._colors = colors or method_colors(r.cell.method_label for r in records)
        self._aggregates = Aggregates(records) if aggregates is None else aggregates
        self._map_style = map_style
        self._plots_dir = out / PLOTS_DIR
        self._plots_dir.mkdir(parents=True, exist_ok=True)
        self._by_dataset: dict[str, list[CellRecord]] = {}
        for rec in records:
            self._by_dataset.setdefault(rec.cell.dataset_label, []).append(rec)
        self._cache = FigureCache(self._plots_dir)
        self._made: dict[str, list[Path]] = {}
        self._digests: dict[str, str] = {}
        self._to_draw: list[str] = []
        for dataset, recs in self._by_dataset.items():
            colors_used = sorted(_colors_of(recs, self._colors).items())
            self._digests[dataset] = inputs_digest(recs, "dataset", dataset, map_style, colors_used)
            cached = self._cache.lookup(f"dataset:{dataset}", self._digests[dataset])
            if cached is not None:
                self._made[dataset] = [self._cache.path(name) for name in cached.payload]
            else:
                self._to_draw.append(dataset)
        self._runtime_digest = inputs_digest(records, "runtime", sorted(self._colors.items()))
        self._runtime_cached = self._cache.lookup("runtime", self._runtime_digest)
        self._tell = progress or (lambda done, total: None)
        self._lock = threading.Lock()
        self._finished: dict[str, int] = {}  # dataset -> its tasks ended (2: run and robustness figures)
        self._pool: ProcessPoolExecutor | None = None
        self._runs: dict[str, Future[dict[str, Path | None]]] = {}
        self._robust: dict[str, Future[dict[str, Path | None]]] = {}
        self._runtime: Future[Path | None] | None = None
        self._tell(0, len(self._to_draw))
        if jobs > 1 and self._to_draw:
            self._start(jobs)

    def _start(self, jobs: int) -> None:
        # spawn: a fresh interpreter per worker, whatever threads or matplotlib state this process holds.
        self._pool = ProcessPoolExecutor(
            min(jobs, len(self._to_draw) + 1), mp_context=multiprocessing.get_context("spawn")
        )
        pool = self._pool
        costs = {dataset: drawing_cost(self._by_dataset[dataset]) for dataset in self._to_draw}
        for dataset in sorted(self._to_draw, key=lambda d: -costs[d]):  # stable: equal costs keep suite order
            read_pictured(self._by_dataset[dataset])  # sent with the records: the worker reads nothing again
            args = (dataset, self._by_dataset[dataset], self._plots_dir, self._colors, self._map_style)
            self._runs[dataset] = pool.submit(_run_figures, *args)
            self._runs[dataset].add_done_callback(self._ended(dataset))
        metrics = self._aggregates.metrics  # the report's own process makes the table meanwhile
        for dataset in self._to_draw:
            self._robust[dataset] = pool.submit(_robustness_figures, dataset, metrics, self._plots_dir, self._colors)
            self._robust[dataset].add_done_callback(self._ended(dataset))
        if self._runtime_cached is None:
            self._runtime = pool.submit(
                plot_runtime, self._aggregates.cost, self._plots_dir / "runtime.png", self._colors
            )

    def _ended(self, dataset: str) -> Callable[[Future[dict[str, Path | None]]], None]:
        def ended(_: Future[dict[str, Path | None]]) -> None:
            with self._lock:
                self._finished[dataset] = self._finished.get(dataset, 0) + 1
                done = sum(1 for count in self._finished.values() if count == 2)
                self._tell(done, len(self._to_draw))

        return ended

    def result(self) -> dict[str, list[Path]]:
        """dataset label -> its PNGs ("" for the cross-dataset runtime figure), once every one is drawn."""
        drawn: dict[str, list[Path]] = {}
        if self._pool is not None:
            for dataset in self._to_draw:
                drawn[dataset] = _ordered({**self._runs[dataset].result(), **self._robust[dataset].result()})
        else:
            for k, dataset in enumerate(self._to_draw):
                args = (self._by_dataset[dataset], self._aggregates.metrics, self._plots_dir, self._colors)
                drawn[dataset] = _dataset_plots(dataset, *args, self._map_style)
                self._tell(k + 1, len(self._to_draw))
        for dataset, files in drawn.items():
            self._made[dataset] = files
            self._cache.store(f"dataset:{dataset}", self._digests[dataset], files, [self._cache.name(f) for f in files])
        made = {dataset: self._made[dataset] for dataset in self._by_dataset}  # suite order, whichever were drawn now
        if self._runtime_cached is not None:
            made[""] = [self._cache.path(name) for name in self._runtime_cached.payload]
        else:
            if self._runtime is not None:
                runtime = self._runtime.result()
            else:
                runtime = plot_runtime(self._aggregates.cost, self._plots_dir / "runtime.png", self._colors)
            made[""] = [runtime] if runtime is not None else []
            self._cache.store("runtime", self._runtime_digest, made[""], [self._cache.name(f) for f in made[""]])
        self._cache.save()
        self.close()
        return made

    def close(self) -> None:
        """Stop the workers (waiting for none that has not started)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def __enter__(self) -> PendingPlots:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        self.close()


def start_plots(
    records: list[CellRecord],
    out: Path,
    colors: dict[str, str] | None = None,
    *,
    map_style: MapStyle = "grid",
    jobs: int = 1,
    progress: PlotProgress | None = None,
    aggregates: Aggregates | None = None,
) -> PendingPlots:
    """Start drawing every plot of the report (PNG, each with an SVG twin); :meth:`PendingPlots.result` waits.

    ``progress`` is told ``(datasets drawn, datasets to draw)`` before the first and as each ends (the CLI's
    bar; figures found in the cache are not counted; from a worker thread when ``jobs`` > 1).
    ``aggregates``: the :class:`Aggregates` of ``records`` (made here otherwise); its tables are read only
    when a figure that needs them is drawn.
    """
    return PendingPlots(records, out, colors, map_style=map_style, jobs=jobs, progress=progress, aggregates=aggregates)


def render_plots(
    records: list[CellRecord],
    out: Path,
    colors: dict[str, str] | None = None,
    *,
    map_style: MapStyle = "grid",
    jobs: int = 1,
    progress: PlotProgress | None = None,
    aggregates: Aggregates | None = None,
) -> dict[str, list[Path]]:
    """Every plot of the report, drawn now: dataset label -> its PNGs ("" for cross-dataset); see start_plots."""
    with start_plots(
        records, out, colors, map_style=map_style, jobs=jobs, progress=progress, aggregates=aggregates
    ) as pending:
        return pending.result()
