"""Build a report or the results page only when something it is built from changed.

The stamp itself is :mod:`albot1.report.build_stamp`; this module says, for
each kind of build, what it reads (its :class:`Source` folders), which of
its options change what it writes, and what it wrote. The builders are
imported only when a build runs: the check that skips one costs a walk of
the stores and no plotting import.

What each build reads:

* ``albot1 report results/<suite>``: the store; for the thesis suite also
  the companion stores it reads beside its own (``results/default``). The
  figures of their reports that its page links (``reports/default/plots/
  *-maps.png``) are not read: which ones are drawn is known from those
  stores (:meth:`albot1.report.thesis.page._Figures.linked`), so the two
  reports can be built at once.
* ``albot1 results-page``: the default store, the thesis store and the
  thesis store's companions; its outputs include the README it rewrites, so
  an edited README is rewritten again.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from albot1.report.build_stamp import BuildStamp, Source, folder_files, forget_all, unsettled
from albot1.report.folders import default_out

if TYPE_CHECKING:
    from albot1.report.column_selection import ColumnSelection
    from albot1.report.figure_pool import PlotProgress
    from albot1.report.map_plots import MapStyle


def report_options(
    results_dir: Path, out: Path, *, plots: bool, map_style: str, columns: str | None = None
) -> dict[str, Any]:
    """What of a report's command changes its bytes (``jobs`` does not: the figures are the same files)."""
    return {
        "kind": "report",
        "results": str(results_dir),  # as given: the pages print it and link relative to it
        "out": os.path.abspath(out),
        "plots": plots,
        "map_style": map_style,
        "columns": columns,  # as given (``--columns``; None: every column)
    }


def column_selection(columns: str | None) -> ColumnSelection:
    """``--columns`` as the tables' selection (ReportError naming a wrong key); None: every column."""
    from albot1.report.collect import COST_COLUMNS, METRIC_COLUMNS
    from albot1.report.column_selection import ALL_COLUMNS, parse_columns

    return ALL_COLUMNS if columns is None else parse_columns(columns, {**METRIC_COLUMNS, **COST_COLUMNS})


def report_sources(results_dir: Path, suite: str) -> list[Source]:
    """The folders a report of ``suite`` reads (see the module docstring)."""
    from albot1.report.thesis.evidence import COMPANION_SUITES
    from albot1.report.thesis.experiments.datasets import THESIS_SUITE

    sources = [Source(Path(results_dir))]
    if suite == THESIS_SUITE:
        sources += [Source(Path(results_dir).parent / name) for name in COMPANION_SUITES]
    return sources


def current_report(
    results_dir: Path, out: Path, *, plots: bool = True, map_style: str = "grid", columns: str | None = None
) -> Path | None:
    """The page of the report in ``out`` when its last build is still what a build would write, else None."""
    options = report_options(results_dir, out, plots=plots, map_style=map_style, columns=columns)
    page = BuildStamp(out).fresh(options)
    return out / page if isinstance(page, str) else None


def report(
    results_dir: Path,
    out: Path | None = None,
    *,
    plots: bool = True,
    map_style: str = "grid",
    columns: str | None = None,
    jobs: int = 1,
    progress: PlotProgress | None = None,
    force: bool = False,
) -> Path:
    """Build the report (:func:`albot1.report.index.build_report`) and stamp it; returns its page.

    Its figures still come from the figure cache when their own runs did
    not change; ``force`` trusts no stamp (the report's, and every figure
    cache's in its folder), so everything is read and drawn again. Check
    :func:`current_report` first to skip a build that would change nothing.
    """
    target = Path(out) if out is not None else default_out(results_dir)
    stamp = BuildStamp(target)
    if force:
        forget_all(target)
    stamp.forget()  # a build that stops half-way leaves no stamp
    from albot1.bench.store import ResultsStore
    from albot1.report.index import build_report

    style: MapStyle = "points" if map_style == "points" else "grid"
    sources = report_sources(results_dir, ResultsStore(results_dir).read_plan().suite)
    options = report_options(results_dir, target, plots=plots, map_style=map_style, columns=columns)
    digest = stamp.digest(sources, options)
    selection = column_selection(columns)
    index = build_report(
        results_dir, target, plots=plots, map_style=style, jobs=jobs, progress=progress, columns=selection
    )
    if not unsettled(target):  # a figure that failed is tried again next time: no skipping until it is drawn
        stamp.record(sources, digest, folder_files(target), index.relative_to(target).as_posix())
    return index


def results_options(default: Path, thesis: Path | None, page: Path, readme: Path | None) -> dict[str, Any]:
    """What of `albot1 results-page`'s command changes its bytes."""
    return {
        "kind": "results-page",
        "default": str(default),
        "thesis": None if thesis is None else str(thesis),
        "page": os.path.abspath(page),
        "readme": None if readme is None else os.path.abspath(readme),
    }


def results_stamp(page: Path) -> BuildStamp:
    """The results page's stamp: beside its figures (``docs/results/build.json``, ignored by git)."""
    return BuildStamp(page.parent / "results")


def current_results_page(default: Path, thesis: Path | None, page: Path, readme: Path | None) -> list[Path] | None:
    """The files the last `albot1 results-page` wrote when they are still what it would write, else None."""
    written = results_stamp(page).fresh(results_options(default, thesis, page, readme))
    if isinstance(written, list) and all(isinstance(w, str) for w in written):
        return [Path(w) for w in written]
    return None


def results_page(default: Path, thesis: Path | None, page: Path, readme: Path | None) -> list[Path]:
    """Write the results page (:func:`albot1.report.results_page.write_results`) and stamp it; what it wrote.

    Check :func:`current_results_page` first to skip a run that would change nothing.
    """
    stamp = results_stamp(page)
    stamp.forget()
    from albot1.report.results_data import build_data
    from albot1.report.results_page import write_results
    from albot1.report.thesis.evidence import COMPANION_SUITES

    sources = [Source(default)]
    if thesis is not None:
        sources += [Source(thesis), *[Source(thesis.parent / name) for name in COMPANION_SUITES]]
    unique = list({(s.root, s.pattern): s for s in sources}.values())
    digest = stamp.digest(unique, results_options(default, thesis, page, readme))
    command = f"albot1 results-page {default.as_posix()}" + (f" --thesis {thesis.as_posix()}" if thesis else "")
    written = write_results(build_data(default, thesis, command), page, readme)
    stamp.record(unique, digest, written, [str(w) for w in written])
    return written
