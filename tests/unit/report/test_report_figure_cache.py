"""A report drawn again draws only the figures whose inputs changed (albot1.report.figure_cache).

A tiny store made by the real planner and cell executor (dead reckoning on two small synthetic worlds) is
reported: the first report is built once for the module (:func:`first_report`) and each slow test goes on
from a copy of it; the second report draws nothing; after one cell's metrics change, only its dataset's figures
(and the cross-dataset runtime figure) are drawn again; a deleted figure is drawn again.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any, NamedTuple, cast

import pytest

from albot1 import versions
from albot1.bench.cells import execute_cell
from albot1.bench.grid import Cell
from albot1.bench.plan import plan_suite
from albot1.bench.store import ResultsStore
from albot1.bench.suite import parse_suite
from albot1.report import figure_pool, tables
from albot1.report.collect import CellRecord
from albot1.report.figure_cache import STAMPS, FigureCache, inputs_digest
from albot1.report.index import build_report
from albot1.settings import get_settings

DATASETS = ("synthetic-office-loop", "synthetic-corridor")


@pytest.fixture(scope="module")
def results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    data = {
        "description": "two worlds, dead reckoning",
        "grid": {"degradations": ["gauss:0.05:1"], "seeds": [0]},
        "methods": [{"name": "odometry"}],
        "datasets": [{"name": name} for name in DATASETS],
    }
    suite = parse_suite(data, name="tiny", source="tiny.toml")
    plan = plan_suite(suite, get_settings())
    root = tmp_path_factory.mktemp("results") / "tiny"
    store = ResultsStore(root)
    store.write_plan(plan)
    for cell in plan.cells:
        execute_cell(cell, store.runs)
    return root


class FirstReport(NamedTuple):
    """The store's first report and what building it did (recorded by the spies below)."""

    folder: Path
    drawn: list[str]
    aggregated: int


@pytest.fixture(scope="module")
def first_report(results: Path, tmp_path_factory: pytest.TempPathFactory) -> FirstReport:
    """The store's report built once, before any test edits the store: the slow tests go on from a copy of it.

    A copy with its file times kept is what a second build into the same folder finds (the figure cache names
    its files relative to the folder), so the module draws the two datasets' figures once instead of once per
    test; the second build's claims are checked on the copy.
    """
    folder = tmp_path_factory.mktemp("first") / "report"
    with pytest.MonkeyPatch.context() as patch:
        drawn = _counting(patch)
        aggregated = _aggregating(patch)
        build_report(results, folder)
    return FirstReport(folder, drawn, len(aggregated))


def _copy(report: FirstReport, out: Path) -> Path:
    """A copy of the first report to build into (file times kept, as the folder the first build left)."""
    shutil.copytree(report.folder, out)
    return out


def _counting(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    drawn: list[str] = []
    original: Callable[..., list[Path]] = figure_pool._dataset_plots

    def spy(dataset: str, *args: Any) -> list[Path]:
        drawn.append(dataset)
        return original(dataset, *args)

    monkeypatch.setattr(figure_pool, "_dataset_plots", spy)
    return drawn


def _aggregating(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    calls: list[int] = []
    original: Callable[..., Any] = tables.aggregate

    def spy(*args: Any) -> Any:
        calls.append(1)
        return original(*args)

    monkeypatch.setattr(tables, "aggregate", spy)
    return calls


@pytest.mark.slow
def test_a_second_report_draws_nothing_and_a_changed_cell_redraws_its_dataset_only(
    results: Path, first_report: FirstReport, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert sorted(first_report.drawn) == sorted(DATASETS)
    assert first_report.aggregated == 2  # accuracy and cost, once each: the tables, figures and index.html share them
    out = _copy(first_report, tmp_path / "report")
    first = {p.name: p.read_bytes() for p in (out / "plots").glob("*.png")}
    readme = (out / "README.md").read_text(encoding="utf-8")

    drawn = _counting(monkeypatch)
    aggregated = _aggregating(monkeypatch)
    build_report(results, out)
    assert drawn == []
    assert len(aggregated) == 2  # the tables are written again; the figures, all kept, need no aggregate
    assert {p.name: p.read_bytes() for p in (out / "plots").glob("*.png")} == first
    assert (out / "README.md").read_text(encoding="utf-8") == readme  # the same figures are linked

    # one cell of the corridor evaluated again (its metrics.json rewritten with other bytes)
    metrics = next(
        p for p in results.rglob("metrics.json") if '"synthetic-corridor' in (p.parent / "result.json").read_text()
    )
    metrics.write_text(json.dumps(json.loads(metrics.read_text()), indent=3))
    drawn.clear()
    build_report(results, out)
    assert drawn == ["synthetic-corridor"]

    # a figure deleted by hand is drawn again
    next((out / "plots").glob("synthetic-office-loop-*.png")).unlink()
    drawn.clear()
    build_report(results, out)
    assert drawn == ["synthetic-office-loop"]


def test_damaged_or_foreign_stamps_are_ignored(tmp_path: Path) -> None:
    figure = tmp_path / "a.png"
    figure.write_bytes(b"png")
    cache = FigureCache(tmp_path)
    cache.store("group", "d1", [figure], ["a.png"])
    cache.save()
    again = FigureCache(tmp_path)
    found = again.lookup("group", "d1")
    assert found is not None and found.files == [figure] and found.payload == ["a.png"]
    assert again.lookup("group", "d2") is None  # another digest: drawn again
    for damaged in ("{", '{"version": 99, "groups": {}}', '{"version": 1, "groups": []}', "[]"):
        (tmp_path / STAMPS).write_text(damaged)
        assert FigureCache(tmp_path).lookup("group", "d1") is None


def test_the_digest_names_the_options(results: Path) -> None:
    assert inputs_digest([], "a", 1) == inputs_digest([], "a", 1)
    assert inputs_digest([], "a", 1) != inputs_digest([], "a", 2)


def _run_folder(root: Path) -> CellRecord:
    """A completed cell whose run folder holds a result, metrics and a trajectory (what the figures draw)."""
    root.mkdir()
    (root / "result.json").write_text('{"scans": 2}')
    (root / "metrics.json").write_text('{"ate": 1.0}')
    (root / "trajectory.tum").write_text("0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n")
    return CellRecord(cast(Cell, SimpleNamespace(key="k")), "done", root, None, None, None)


def test_a_run_file_rewritten_in_place_changes_the_digest(tmp_path: Path) -> None:
    record = _run_folder(tmp_path / "run")
    before = inputs_digest([record], "dataset")
    trajectory = tmp_path / "run" / "trajectory.tum"
    trajectory.write_text(trajectory.read_text().replace("1 1 0", "1 3 0"))  # result and metrics untouched
    assert inputs_digest([record], "dataset") != before  # the trajectory figures show the new poses


def test_a_new_file_in_a_run_folder_changes_the_digest_and_a_hidden_one_does_not(tmp_path: Path) -> None:
    record = _run_folder(tmp_path / "run")
    before = inputs_digest([record], "dataset")
    (tmp_path / "run" / ".tmp-trajectory.tum").write_text("half written")
    assert inputs_digest([record], "dataset") == before
    (tmp_path / "run" / "map.geojson").write_text("{}")
    assert inputs_digest([record], "dataset") != before


def test_another_drawing_library_changes_the_digest(monkeypatch: pytest.MonkeyPatch) -> None:
    before = inputs_digest([], "dataset")
    real = versions.library_versions

    def other_matplotlib(names: tuple[str, ...]) -> dict[str, str | None]:
        return {**real(names), "matplotlib": "0.0.1"}

    monkeypatch.setattr(versions, "library_versions", other_matplotlib)
    assert inputs_digest([], "dataset") != before  # another matplotlib lays the figures out otherwise


def test_a_group_found_out_of_date_is_struck_before_it_is_drawn(tmp_path: Path) -> None:
    figure = tmp_path / "a.png"
    figure.write_bytes(b"drawn from d1")
    cache = FigureCache(tmp_path)
    cache.store("group", "d1", [figure], ["a.png"])
    cache.unsettled("other")
    cache.save()
    # the inputs change to d2: the group is drawn again, and the report is stopped half-way (no save)
    assert FigureCache(tmp_path).lookup("group", "d2") is None
    figure.write_bytes(b"half drawn from d2")
    # the inputs go back to d1: the stamp must not vouch for the files the stopped drawing left
    again = FigureCache(tmp_path)
    assert again.lookup("group", "d1") is None
    assert json.loads((tmp_path / STAMPS).read_text())["unsettled"] == ["other"]  # still tried again


def test_figures_no_longer_drawn_are_deleted_with_their_groups(tmp_path: Path) -> None:
    elsewhere = tmp_path / "other-report" / "maps.png"  # a file of another folder that a group links
    elsewhere.parent.mkdir()
    elsewhere.write_bytes(b"linked")
    folder = tmp_path / "plots"
    folder.mkdir()
    for name in ("a.png", "a.svg", "b.png", "c.png"):
        (folder / name).write_bytes(name.encode())
    cache = FigureCache(folder)
    cache.store("dataset:one", "d1", [folder / "a.png", folder / "b.png", elsewhere])
    cache.store("dataset:two", "d1", [folder / "c.png"])
    cache.save()
    assert sorted(p.name for p in folder.iterdir()) == ["a.png", "a.svg", "b.png", "c.png", STAMPS]
    # the next build: "one" changed and no longer makes b.png; "two" left the store (never looked up)
    again = FigureCache(folder)
    assert again.lookup("dataset:one", "d2") is None
    again.store("dataset:one", "d2", [folder / "a.png"])
    again.save()
    assert sorted(p.name for p in folder.iterdir()) == ["a.png", "a.svg", STAMPS]  # as a fresh build leaves it
    assert elsewhere.read_bytes() == b"linked"
    assert FigureCache(folder).lookup("dataset:two", "d1") is None
    stamps = json.loads((folder / STAMPS).read_text())
    assert sorted(stamps["groups"]) == ["dataset:one"]


def test_what_a_failed_drawing_made_is_not_deleted(tmp_path: Path) -> None:
    (tmp_path / "trace.png").write_bytes(b"drawn")
    cache = FigureCache(tmp_path)
    cache.store("thesis:trace", "d1", [tmp_path / "trace.png"])
    cache.save()
    # drawn again: the first panel is drawn, the second fails (its reason is shown beside the first)
    again = FigureCache(tmp_path)
    assert again.lookup("thesis:trace", "d2") is None
    again.unsettled("thesis:trace", [tmp_path / "trace.png"])
    again.save()
    assert (tmp_path / "trace.png").read_bytes() == b"drawn"  # the page links it


@pytest.mark.slow
def test_a_report_without_plots_removes_the_figures_an_earlier_report_drew_there(
    results: Path, first_report: FirstReport, tmp_path: Path
) -> None:
    """``--no-plots`` into a folder with an earlier report's figures left them there, with that report's numbers."""
    out = _copy(first_report, tmp_path / "report")
    drawn = sorted(p.name for p in (out / "plots").rglob("*.png"))
    assert drawn  # the earlier report's figures
    (out / "plots" / "mine.txt").write_text("not the report's")
    build_report(results, out, plots=False)
    assert sorted(p.name for p in (out / "plots").rglob("*.png")) == []
    assert sorted(p.name for p in (out / "plots").rglob("*.svg")) == []
    assert (out / "plots" / "mine.txt").read_text() == "not the report's"  # a file no stamp names stays
    assert "plots/" not in (out / "README.md").read_text()
