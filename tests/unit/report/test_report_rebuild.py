"""An incremental report is the report a full rebuild gives, and is built only when something changed.

A tiny store made by the real planner and cell executor (dead reckoning on a
small synthetic world, two seeds) is reported into one folder: the second
`albot1 report` builds nothing; after one cell's metrics change the report is
built again and is byte for byte what ``--force`` (everything read and drawn
again) gives; a deleted output is written again (albot1.report.rebuild).
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest
from typer.testing import CliRunner

from albot1.bench.cells import execute_cell
from albot1.bench.plan import plan_suite
from albot1.bench.store import ResultsStore
from albot1.bench.suite import parse_suite
from albot1.cli.app import app
from albot1.report import rebuild
from albot1.report.build_stamp import STAMP
from albot1.report.collect import collect
from albot1.report.figure_cache import STAMPS
from albot1.report.plots import representative
from albot1.settings import get_settings


@pytest.fixture(scope="module")
def results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    data = {
        "description": "one world, dead reckoning",
        "grid": {"degradations": ["gauss:0.05:1"], "seeds": [0, 1]},
        "methods": [{"name": "odometry"}],
        "datasets": [{"name": "synthetic-corridor"}],
    }
    plan = plan_suite(parse_suite(data, name="tiny", source="tiny.toml"), get_settings())
    root = tmp_path_factory.mktemp("results") / "tiny"
    store = ResultsStore(root)
    store.write_plan(plan)
    for cell in plan.cells:
        execute_cell(cell, store.runs)
    return root


#: Makes a folder holding a fresh report of the store as it stands (a copy, file times kept).
FreshReport = Callable[[Path], Path]


@pytest.fixture(scope="module")
def fresh_report(results: Path, tmp_path_factory: pytest.TempPathFactory) -> FreshReport:
    """``fresh_report(out)``: ``out`` holds the store's report, built there from a copy of one built from nothing.

    The figures are drawn once and copied (file times kept: the figure cache names its files relative to the
    folder, so the build in the copy draws none) to every test that starts from a fresh report; they are drawn
    again only when the store changed since (a test edited it), so each copy is the store's current report.
    """
    built = tmp_path_factory.mktemp("fresh") / "report"

    def copy(out: Path) -> Path:
        if rebuild.current_report(results, built) is None:
            shutil.rmtree(built, ignore_errors=True)
            rebuild.report(results, built)
        shutil.copytree(built, out)
        rebuild.report(results, out)  # stamped for this folder (a stamp names its folder); the figures are cached
        assert rebuild.current_report(results, out) == out / "README.md"
        return out

    return copy


def _contents(folder: Path) -> dict[str, bytes]:
    """Every file of a report but the stamps (they hold modification times)."""
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name not in (STAMP, STAMPS)
    }


@pytest.mark.slow
def test_an_incremental_report_equals_a_full_rebuild(results: Path, tmp_path: Path) -> None:
    out = tmp_path / "report"
    runner = CliRunner()
    first = runner.invoke(app, ["report", str(results), "--out", str(out)])
    assert first.exit_code == 0, first.output
    assert "up to date" not in first.output
    assert rebuild.current_report(results, out) == out / "README.md"

    again = runner.invoke(app, ["report", str(results), "--out", str(out)])
    assert again.exit_code == 0, again.output
    assert f"report: {out / 'README.md'} (up to date: nothing it is built from changed)" in again.output
    before = _contents(out)

    ResultsStore(results).write_plan(ResultsStore(results).read_plan())  # what every `albot1 bench` does
    assert rebuild.current_report(results, out) == out / "README.md"
    assert rebuild.current_report(results, out, map_style="points") is None

    # one cell evaluated again with another number
    metrics = sorted(results.rglob("metrics.json"))[0]
    record = json.loads(metrics.read_text())
    record["ate"]["rmse_m"] = record["ate"]["rmse_m"] * 2 + 1
    metrics.write_text(json.dumps(record, indent=2))
    assert rebuild.current_report(results, out) is None
    rebuild.report(results, out)
    incremental = _contents(out)
    assert incremental != before
    assert incremental["cells.csv"] != before["cells.csv"]

    rebuild.report(results, out, force=True)
    assert _contents(out) == incremental

    (out / "metrics.tex").unlink()
    assert rebuild.current_report(results, out) is None
    rebuild.report(results, out)
    assert _contents(out) == incremental
    assert rebuild.current_report(results, out) == out / "README.md"


@pytest.mark.slow
def test_a_page_the_store_no_longer_makes_is_removed(results: Path, fresh_report: FreshReport, tmp_path: Path) -> None:
    """Another store's report (or this store's, before cells went) left pages this store does not make.

    The folder holds this store's own report besides (a copy of a fresh build, file times kept): its figures come
    from the figure cache, so the test draws none; the pages are written and removed as before.
    """
    fresh = fresh_report(tmp_path / "fresh")
    out = tmp_path / "report"
    shutil.copytree(fresh, out)
    stale = [
        "generalisation.md",
        "generalisation.csv",
        "standard-benchmark.md",
        "standard-benchmark.csv",
        "standard-benchmark-paired.csv",  # the page's paired comparisons stayed (their verdicts, old numbers)
    ]
    for name in stale:
        (out / name).write_text("numbers of an earlier report\n")
    rebuild.report(results, out)
    assert sorted(_contents(out)) == sorted(_contents(fresh))
    assert not any((out / name).exists() for name in stale)


@pytest.mark.slow
def test_a_run_file_edited_in_place_with_its_time_put_back_is_drawn_again(
    results: Path, fresh_report: FreshReport, tmp_path: Path
) -> None:
    """A trajectory rewritten with its size and modification time kept: the rebuilt report is a fresh one.

    Runs after the stale-page test (it edits the store, which would make that test's shared fresh report stale).
    """
    out = fresh_report(tmp_path / "report")
    pictured = representative(collect(results)[1])["odometry"]  # the run the trajectory figures draw
    trajectory = pictured.run_dir / "trajectory.tum"
    lines = trajectory.read_text().splitlines(keepends=True)
    fields = lines[2].split(" ")  # the second pose (after the header line)
    fields[1] = f"{float(fields[1]) + 0.5:.9f}"  # half a metre off in x, written as wide: the same size
    lines[2] = " ".join(fields)
    st = trajectory.stat()
    trajectory.write_text("".join(lines))
    os.utime(trajectory, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert trajectory.stat().st_size == st.st_size
    assert rebuild.current_report(results, out) is None  # the store's bytes changed
    before = _contents(out)
    rebuild.report(results, out)
    incremental = _contents(out)
    changed = {name for name in incremental if incremental[name] != before.get(name)}
    assert any(name.endswith("-trajectories.png") for name in changed)  # the figure shows the edited poses
    rebuild.report(results, out, force=True)
    assert _contents(out) == incremental
