"""The order in which a report's figures are handed to worker processes, and the order its index lists them.

Exact expectations on made-up run folders (their file sizes are the cost estimate); that the drawn files
are the same with and without workers is checked by ``test_report_html.py`` (``jobs=2`` against ``jobs=1``).
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import cast

from albot1.report.collect import CellRecord
from albot1.report.figure_pool import KINDS, ROBUSTNESS, _ordered, drawing_cost


def _record(folder: Path, method: str, seed: int, sizes: dict[str, int], status: str = "done") -> CellRecord:
    folder.mkdir(parents=True)
    for name, size in sizes.items():
        (folder / name).write_bytes(b"x" * size)
    cell = SimpleNamespace(method_label=method, degradation="none", seed=seed)
    result = SimpleNamespace(map_file="map.geojson")
    return cast(CellRecord, SimpleNamespace(cell=cell, status=status, run_dir=folder, result=result))


def test_the_cost_is_every_done_runs_trajectories_and_the_pictured_runs_maps(tmp_path: Path) -> None:
    records = [
        _record(tmp_path / "a0", "a", 0, {"trajectory.tum": 10, "reference.tum": 5, "map.geojson": 1000}),
        _record(tmp_path / "a1", "a", 1, {"trajectory.tum": 20, "map.geojson": 7000}),  # not pictured: seed 1
        _record(tmp_path / "b0", "b", 0, {"trajectory.tum": 3, "map.geojson": 100}),
        _record(tmp_path / "c0", "c", 0, {"trajectory.tum": 99, "map.geojson": 99}, status="failed"),
    ]
    assert drawing_cost(records) == (10 + 5) + 20 + 3 + 1000 + 100
    assert drawing_cost([]) == 0


def test_a_datasets_figures_keep_their_order_whichever_task_drew_them(tmp_path: Path) -> None:
    drawn: dict[str, Path | None] = {kind: tmp_path / f"d-{kind}.png" for kind in reversed(KINDS)}
    drawn["relation-boxes"] = None  # no relations: not drawn
    names = [p.name for p in _ordered(drawn)]
    robustness = [f"d-{kind}.png" for _, _, kind in ROBUSTNESS]
    expected = ["d-trajectories.png", "d-ape.png", "d-error-distance.png", "d-rpe-boxes.png", "d-maps.png"]
    assert names == [*expected, *robustness, "d-scan-time.png"]


class _Run:
    """A record's reading, counted (what read_pictured asks of a CellRecord)."""

    def __init__(self, method: str, seed: int, status: str = "done", broken: bool = False) -> None:
        self.cell = SimpleNamespace(method_label=method, degradation="none", seed=seed)
        self.status = status
        self.broken = broken
        self.read: list[str] = []

    def stored_run(self) -> None:
        if self.broken:
            from albot1.runs.errors import RunError

            raise RunError("trajectory.tum: damaged")
        self.read.append("run")

    def map_geometry(self) -> None:
        self.read.append("map")


def test_the_pictured_runs_are_read_before_the_workers_get_them_and_a_damaged_one_is_left() -> None:
    from albot1.report.figure_pool import read_pictured

    pictured, other, failed, broken = _Run("a", 0), _Run("a", 1), _Run("b", 0, "failed"), _Run("c", 0, broken=True)
    read_pictured(cast(list[CellRecord], [other, pictured, failed, broken]))  # the lowest seed is pictured
    assert pictured.read == ["run", "map"]
    assert other.read == [] and failed.read == [] and broken.read == []  # the damaged one fails in its figure
