"""A page's "Regenerate" command names a user's own suite by its path, a shipped suite by its name."""

from __future__ import annotations

from pathlib import Path

from albot1.bench.grid import Cell, GridPlan
from albot1.bench.suite import find_suite
from albot1.data.degrade import parse_spec
from albot1.report import generalisation, standard
from albot1.report.collect import CellRecord
from albot1.report.generalisation import Comparison
from albot1.report.index import write_index
from albot1.report.provenance import bench_argument, bench_command, regenerate_command, rerun_command


def _plan(name: str, path: Path | None) -> GridPlan:
    return GridPlan(name, str(path) if path else None, "", [], [], [], {}, [0], ["none"], {"platform": "test"})


def test_a_shipped_suite_is_named_and_an_own_suite_file_is_given_by_path(tmp_path: Path) -> None:
    assert bench_argument(_plan("quick", find_suite("quick").resolve())) == "quick"
    own = tmp_path / "robot.toml"
    own.write_text('[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "x"\n')
    assert bench_argument(_plan("robot", own)) == str(own)  # `albot1 bench robot` would not find it
    shadow = tmp_path / "quick.toml"  # an own file named like a shipped suite is not that suite
    shadow.write_text(own.read_text())
    assert bench_argument(_plan("quick", shadow)) == str(shadow)
    assert bench_argument(_plan("quick", None)) == "quick"


def test_the_command_names_a_results_folder_elsewhere_and_a_report_folder_elsewhere(tmp_path: Path) -> None:
    quick = _plan("quick", find_suite("quick").resolve())
    assert regenerate_command(quick) == "albot1 bench quick && albot1 report results/quick"
    assert regenerate_command(quick, Path("results/quick"), Path("reports/quick")) == (
        "albot1 bench quick && albot1 report results/quick"
    )
    store = tmp_path / "my results" / "quick"
    assert regenerate_command(quick, store, Path("reports/quick")) == (
        f"albot1 bench quick --results '{tmp_path}/my results' && albot1 report '{store}'"
    )
    assert regenerate_command(quick, Path("res/quick"), tmp_path / "page") == (
        f"albot1 bench quick --results res && albot1 report res/quick --out {tmp_path}/page"
    )
    # a store renamed after the run: `albot1 bench` writes RESULTS/<suite>, so that is the folder reported again
    assert regenerate_command(quick, Path("res/old-quick"), Path("reports/old-quick")) == (
        "albot1 bench quick --results res && albot1 report res/quick --out reports/old-quick"
    )
    assert rerun_command(quick, Path("res/quick")) == "albot1 bench quick --results res"
    assert bench_command("thesis", Path("results")) == "albot1 bench thesis"


def test_the_generalisation_and_standard_pages_print_the_results_folder_they_were_drawn_from(tmp_path: Path) -> None:
    plan = _plan("quick", find_suite("quick").resolve())
    store = tmp_path / "elsewhere" / "quick"
    expected = f"Regenerate: `albot1 bench quick --results {tmp_path}/elsewhere && albot1 report {store}"
    row = Comparison("drive", "kiss-icp", "none", 1, 0, 1.0, 1.0, 1.0, 1.0, 1.0, "same", None, None, None, None, None)
    page = generalisation.render_page(plan, [row], regenerate=regenerate_command(plan, store))
    assert f"{expected}`." in page
    assert "Regenerate: `albot1 bench quick && albot1 report results/quick`." in generalisation.render_page(plan, [row])
    text = standard.render_page(plan, [], {}, regenerate=regenerate_command(plan, store))
    assert f"{expected}` (`make bench`" in text


def test_the_index_says_how_to_resume_cells_not_run_into_the_same_results_folder(tmp_path: Path) -> None:
    plan = _plan("quick", find_suite("quick").resolve())
    cell = Cell("quick", "drive", "drive", "odometry", "odometry", "default", "none", 0, "k", "v", 1.0, 1.0)
    store = tmp_path / "elsewhere" / "quick"
    tables = {name: tmp_path / name for name in ("metrics.md", "metrics.csv", "metrics.tex", "cost.md", "cost.csv")}
    tables |= {name: tmp_path / name for name in ("cost.tex", "cells.csv", "cells-cost.csv")}
    rec = CellRecord(cell, "not run", store / "runs" / "k", None, None, None)
    index = write_index(plan, [rec], tables, {}, tmp_path, store)
    line = (
        f"The runner stopped before these cells finished; run `albot1 bench quick --results {tmp_path}/elsewhere` again"
    )
    assert line in index.read_text()


def test_the_index_names_every_degradation_that_runs_with_one_seed(tmp_path: Path) -> None:
    # offset:DX:DY:DTH is as deterministic as bias: the generalisation suite runs it once, and the index said only
    # `none`, `thesis` and `bias:...` ran with the first seed.
    plan = _plan("quick", find_suite("quick").resolve())
    cell = Cell("quick", "drive", "drive", "odometry", "odometry", "default", "none", 0, "k", "v", 1.0, 1.0)
    tables = {name: tmp_path / name for name in ("metrics.md", "metrics.csv", "metrics.tex", "cost.md", "cost.csv")}
    tables |= {name: tmp_path / name for name in ("cost.tex", "cells.csv", "cells-cost.csv")}
    rec = CellRecord(cell, "not run", tmp_path / "runs" / "k", None, None, None)
    seeds = next(
        line
        for line in write_index(plan, [rec], tables, {}, tmp_path, tmp_path).read_text().splitlines()
        if line.startswith("- seeds: ")
    )
    for spec in ("thesis", "bias:0.02:0.5", "offset:0.2:0.05:2"):
        assert not parse_spec(spec).seeded
        kind = parse_spec(spec).kind
        assert f"`{kind}`" in seeds or f"`{kind}:...`" in seeds
    assert "gauss" not in seeds and "dropout" not in seeds
