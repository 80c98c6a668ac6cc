"""A suite names another system's trajectory files as a method: scored, stored and reported beside the runs."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from albot1.bench.errors import SuiteError
from albot1.bench.external import dataset_stem
from albot1.bench.plan import plan_suite
from albot1.bench.suite import load_suite
from albot1.report.collect import cell_rows, collect
from albot1.settings import get_settings

# `albot1 bench` end to end (its grid in worker processes): the end-to-end lane (Makefile, `make test-end-to-end`)
pytestmark = pytest.mark.end_to_end

DATASET = "synthetic-office-startstop"


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", "from albot1.cli.app import main; main()", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=600,
    )


def test_dataset_stem_drops_slices_options_and_suffixes() -> None:
    assert dataset_stem("aces[:500]") == "aces"
    assert dataset_stem("intel-corrected?odometry=laser-pose") == "intel-corrected"
    assert dataset_stem("bags/run.mcap") == "run"
    assert dataset_stem("run.clf.gz") == "run"


def test_a_missing_file_and_a_bad_entry_are_suite_errors(tmp_path: Path) -> None:
    suite = tmp_path / "s.toml"
    suite.write_text(
        f'[[methods]]\nname = "carto"\ntrajectories = "carto/{{dataset}}.tum"\n\n[[datasets]]\nname = "{DATASET}"\n'
    )
    with pytest.raises(
        SuiteError, match=rf"no trajectory file for dataset '{DATASET}': expected .*carto/{DATASET}.tum"
    ):
        plan_suite(load_suite(suite), get_settings())
    suite.write_text(
        f'[[methods]]\nname = "kiss-icp"\ntrajectories = "k/{{dataset}}.tum"\n\n[[datasets]]\nname = "{DATASET}"\n'
    )
    with pytest.raises(SuiteError, match="'kiss-icp' is a method this project runs; name another system's output"):
        plan_suite(load_suite(suite), get_settings())
    suite.write_text('[[methods]]\nname = "carto"\ntrajectories = "carto.tum"\n\n[[datasets]]\nname = "x"\n')
    with pytest.raises(SuiteError, match=r"has no \{dataset\}"):
        load_suite(suite)
    suite.write_text(
        '[[methods]]\nname = "c"\ntrajectories = "{dataset}.tum"\npreset = "plus"\n\n[[datasets]]\nname = "x"\n'
    )
    with pytest.raises(SuiteError, match="preset cannot go with trajectories"):
        load_suite(suite)


def test_external_trajectory_is_scored_beside_the_runs_and_reported(tmp_path: Path) -> None:
    """The odometry method's own poses, given back as a TUM file, score digit for digit like its run."""
    results = tmp_path / "results"
    runs_only = tmp_path / "mine.toml"
    runs_only.write_text(
        '[grid]\ndegradations = ["gauss:0.05:0.5"]\nseeds = [0, 1]\n\n'
        f'[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "{DATASET}"\nlimit = 80\n'
    )
    done = _cli("bench", str(runs_only), "-j", "1", "--results", str(results), "--no-progress", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    plan, records = collect(results / "mine")
    run = next(r for r in records if r.cell.degradation == "none")
    (tmp_path / "other").mkdir()
    tum = tmp_path / "other" / f"{DATASET}.tum"
    shutil.copy(run.run_dir / "trajectory.tum", tum)

    runs_only.write_text(
        runs_only.read_text()
        + '\n[[methods]]\nname = "mysys"\ntrajectories = "other/{dataset}.tum"\ntrajectory_format = "tum"\n'
    )
    done = _cli("bench", str(runs_only), "-j", "1", "--results", str(results), "--no-progress", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    plan, records = collect(results / "mine")
    external = [r for r in records if r.cell.trajectory is not None]
    assert [(r.cell.method_label, r.cell.degradation, r.status) for r in external] == [
        ("mysys (external)", "none", "done")
    ]  # one cell: the file is the other system's run on the log itself, not on our degraded copies
    rows = {(row["method"], row["degradation"]): row for row in cell_rows(records)}
    ours, theirs = rows[("odometry", "none")], rows[("mysys (external)", "none")]
    for column in ("ate_rmse_m", "rpe_frame_m", "rpe_frame_deg", "drift_10m_m"):
        assert theirs[column] == ours[column], column
    assert theirs["per_scan_ms_median"] is None and theirs["total_s"] is None
    assert theirs["total_s_na"] == "an external trajectory comes without timings or counters (not measured)"
    sha = hashlib.sha256(tum.read_bytes()).hexdigest()
    metrics = json.loads((external[0].run_dir / "metrics.json").read_text())
    assert metrics["trajectory"]["sha256"] == sha and metrics["map_shape"] is None
    assert json.loads((external[0].run_dir / "result.json").read_text())["config"]["sha256"] == sha

    done = _cli("report", str(results / "mine"), "--out", str(tmp_path / "report"), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    pages = "\n".join(p.read_text() for p in (tmp_path / "report").rglob("*") if p.suffix in {".md", ".html", ".csv"})
    assert "mysys (external)" in pages
    assert sha in pages
    maps = next((tmp_path / "report" / "plots").glob("*-maps.svg")).read_text()
    assert "no map: an external trajectory file" in maps


def test_standard_page_shows_an_external_system_beside_ours_and_the_published_rows(tmp_path: Path) -> None:

    if not (Path(os.environ.get("ALBOT1_DATA_DIR", "/nonexistent")) / "radish" / "aces.clf.bz2").is_file():
        pytest.skip("the ACES log is not in ALBOT1_DATA_DIR")
    results = tmp_path / "results"
    suite = tmp_path / "std.toml"
    suite.write_text('[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "aces"\n')
    done = _cli("bench", str(suite), "-j", "1", "--results", str(results), "--no-progress", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    (run,) = collect(results / "std")[1]
    (tmp_path / "carto").mkdir()
    shutil.copy(run.run_dir / "trajectory.tum", tmp_path / "carto" / "aces.tum")
    suite.write_text(suite.read_text() + '\n[[methods]]\nname = "carto"\ntrajectories = "carto/{dataset}.tum"\n')
    done = _cli("bench", str(suite), "-j", "1", "--results", str(results), "--no-progress", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    # the tables only: the standard page is written apart from the figures (the test above and the README's worked
    # example draw an external system's figures), and drawing whole-log aces plots would be most of this test's time
    done = _cli("report", str(results / "std"), "--out", str(tmp_path / "report"), "--no-plots", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    page = (tmp_path / "report" / "standard-benchmark.md").read_text()
    ours = next(line for line in page.splitlines() if line.startswith("| odometry | measured |"))
    theirs = next(line for line in page.splitlines() if line.startswith("| carto (external) | measured |"))
    # the same poses: the same relation numbers; no timing for a file (n/a), ours measured
    assert theirs.split("|")[3:9] == ours.split("|")[3:9]
    assert theirs.rstrip(" |").endswith("n/a | n/a | n/a") and not ours.rstrip(" |").endswith("n/a")
    assert "| Cartographer (Hess et al. 2016) | **published** |" in page
    sha = hashlib.sha256((tmp_path / "carto" / "aces.tum").read_bytes()).hexdigest()
    assert f"sha256 {sha}" in page
