"""The thesis page links the default report's maps figures from the default store alone, never from its files.

`make bench` builds reports/default and reports/thesis at once, so the page must be the same whether the
default report has drawn its figures yet or not: the figures it will draw are known from its store (a
dataset with a completed run gets one, named by the report's dataset label).
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

from albot1.bench.grid import Cell
from albot1.bench.store import Failure
from albot1.report.collect import CellRecord
from albot1.report.map_plots import draws_maps, maps_drawn
from albot1.report.thesis.evidence import Evidence, Store
from albot1.report.thesis.experiments import Section
from albot1.report.thesis.experiments.common import FigureRequest
from albot1.report.thesis.page import Drawn, _Figures, _section_lines


def _record(dataset: str, method: str, *, status: str = "done", data: str = "d0") -> CellRecord:
    cell = Cell(
        suite="default",
        dataset=dataset,
        dataset_label=dataset,
        method=method,
        method_label=method,
        preset="default",
        degradation="none",
        seed=0,
        key=f"{dataset}-{method}-{data}",
        code_version="v",
        time_s=10,
        memory_mb=100,
    )
    if status != "done":
        failure = Failure("RuntimeError: boom", "exception", 2, 0.1, None)
        return CellRecord(cell, status, Path("/nonexistent"), None, None, failure)
    result = SimpleNamespace(dataset_info=SimpleNamespace(data_sha256={"log": data * 32}))
    return CellRecord(cell, "done", Path("/nonexistent"), cast(Any, result), None, None)


RECORDS = [
    _record("aces", "odometry"),
    _record("aces", "albot1", status="failed"),
    _record("intel", "odometry", status="failed"),  # no completed run: no maps figure
    _record("fr079", "odometry", data="aa"),  # two data identities: the report labels them apart
    _record("fr079", "albot1", data="bb"),
]


def test_a_dataset_gets_a_maps_figure_when_some_run_completed_under_the_reports_label() -> None:
    assert draws_maps(RECORDS[:2]) and not draws_maps(RECORDS[2:3])
    drawn = maps_drawn(RECORDS)
    assert "aces" in drawn and "intel" not in drawn and "fr079" not in drawn
    assert sorted(d for d in drawn if d.startswith("fr079 @")) == sorted(drawn - {"aces"}) and len(drawn) == 3


def _figures(tmp_path: Path, companions: list[CellRecord] | None) -> _Figures:
    plan = cast(Any, SimpleNamespace(machine={}))
    stores = [Store("thesis", tmp_path / "results" / "thesis", plan, [])]
    if companions is not None:
        stores.append(Store("default", tmp_path / "results" / "default", plan, companions))
    return _Figures(Evidence(stores), tmp_path / "reports" / "thesis", {})


def test_the_link_is_made_before_the_default_report_draws_the_figure(tmp_path: Path) -> None:
    figures = _figures(tmp_path, RECORDS)
    [drawn] = figures.draw(FigureRequest("linked-maps", "exp1-maps-aces", "maps of `aces` (default suite)", "aces"))
    assert drawn == Drawn(
        "maps of `aces` (`default` report)", tmp_path / "reports/default/plots/aces-maps.png", None, True
    )
    assert not drawn.path.exists()  # type: ignore[union-attr]
    section = Section("exp1", "Experiment 1", "", "", figures=[FigureRequest("linked-maps", "m", "c", "aces")])
    lines = _section_lines(section, {"m": [drawn]}, figures.out)
    assert "- [maps of `aces` (`default` report)](../default/plots/aces-maps.png) " in "\n".join(lines)
    assert "([SVG](../default/plots/aces-maps.svg))" in "\n".join(lines)  # the report draws both, always


def test_no_link_and_the_reason_when_no_report_draws_the_figure(tmp_path: Path) -> None:
    request = FigureRequest("linked-maps", "exp1-maps-intel", "maps of `intel` (default suite)", "intel")
    [none] = _figures(tmp_path, RECORDS).draw(request)
    assert none.path is None and none.linked
    assert (
        none.reason
        == f"no completed run of this dataset in `{tmp_path / 'results' / 'default'}`: no report draws its maps"
    )
    [absent] = _figures(tmp_path, None).draw(request)
    assert absent.path is None and absent.reason is not None and "no companion store" in absent.reason
