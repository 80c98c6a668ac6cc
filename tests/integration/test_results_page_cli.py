"""`albot1 results-page` on a real (small, synthetic) store: the numbers are the stored ones, re-runs are stable."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from albot1.report.collect import collect
from albot1.report.results_data import THESIS_SPEED_NOTE, load_data
from albot1.report.results_page import readme_block, render_readme_block

pytestmark = [pytest.mark.end_to_end, pytest.mark.slow]

SUITE = """
[grid]
degradations = ["gauss:0.1:1"]
seeds = [0, 1]
undegraded_seeds = [0]

[[methods]]
name = "odometry"

[[datasets]]
name = "synthetic-office-startstop"
"""


def _albot1(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", "from albot1.cli.app import main; main()", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=600,
    )


def test_results_page_quotes_the_stored_ate_and_is_byte_stable(tmp_path: Path) -> None:
    (tmp_path / "small.toml").write_text(SUITE, encoding="utf-8")
    done = _albot1("bench", "small.toml", "-j", "1", "--results", "results", "--no-progress", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    readme = tmp_path / "README.md"
    readme.write_text(f"# mine\n\n{render_readme_block(None)}\n\nafter\n", encoding="utf-8")
    args = ("results-page", "results/small", "--thesis", "results/none", "--out", "docs/results.md")
    done = _albot1(*args, "--readme", "README.md", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    notice = (
        "results-page: NOTICE: --thesis results/none is not a results folder (no grid.json): the page shows no "
        "verdicts and no column of the methods only the thesis suite runs"
    )
    assert done.stderr.splitlines() == [notice]  # a mistyped --thesis is said, not only noted deep in the page
    data = load_data(tmp_path / "docs" / "results" / "results.json")
    assert data is not None
    stored: dict[tuple[str, int], list[float]] = {}
    for folder in (tmp_path / "results" / "small" / "runs").iterdir():
        result = json.loads((folder / "result.json").read_text(encoding="utf-8"))
        metrics = json.loads((folder / "metrics.json").read_text(encoding="utf-8"))
        stored.setdefault((result["degradation"], result["seed"]), []).append(metrics["ate"]["rmse_m"])
    got: dict[tuple[str, int], list[float]] = {}
    for cell in data.ate:
        assert cell.dataset == "synthetic-office-startstop" and cell.rmse_m is not None
        got.setdefault((cell.degradation, cell.seed), []).append(cell.rmse_m)
    assert {k: sorted(v) for k, v in got.items()} == {k: sorted(v) for k, v in stored.items()}
    assert set(got) == {("none", 0), ("gauss:0.1:1", 0), ("gauss:0.1:1", 1)}
    block = readme_block(readme.read_text(encoding="utf-8"), "README.md")
    assert block == render_readme_block(data)
    for values in stored.values():
        for value in values:
            assert f"{value:.4f}" in block
    assert any("results/none is not a results folder" in note for note in data.notes)
    assert data.standard and all(row.kind == "published" for row in data.standard)  # no standard log in this suite
    stamp = data.stores[0]
    assert (stamp.suite, stamp.cells, stamp.done, stamp.failed) == ("small", 3, 3, 0)
    before = {p: p.read_bytes() for p in (tmp_path / "docs").rglob("*") if p.is_file()}
    again = _albot1(*args, "--readme", "README.md", cwd=tmp_path)
    assert again.returncode == 0 and again.stderr.splitlines() == [notice]  # said on an up-to-date run too
    assert {p: p.read_bytes() for p in (tmp_path / "docs").rglob("*") if p.is_file()} == before


def test_the_standard_table_takes_the_methods_the_default_store_lacks_from_the_thesis_store(tmp_path: Path) -> None:
    """As `make bench` shows Albot1+: the thesis suite runs it on the standard logs, the default suite does not.

    Stand-ins (cheap): the "thesis" store (a suite named thesis: --thesis refuses another suite's store) runs
    odometry (also in the default store: not taken again) and odometry's `sparse-map` preset (taken, with its
    store named and no speed) on the whole ACES log.
    """
    if not (Path(os.environ.get("ALBOT1_DATA_DIR", "/nonexistent")) / "radish" / "aces.clf.bz2").is_file():
        pytest.skip("the ACES log is not in ALBOT1_DATA_DIR")
    (tmp_path / "std.toml").write_text('[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "aces"\n')
    (tmp_path / "thesis.toml").write_text(
        '[[methods]]\nname = "odometry"\n\n[[methods]]\nname = "odometry"\npreset = "sparse-map"\n\n'
        '[[datasets]]\nname = "aces"\n'
    )
    for suite in ("std.toml", "thesis.toml"):
        done = _albot1("bench", suite, "-j", "1", "--results", "results", "--no-progress", cwd=tmp_path)
        assert done.returncode == 0, done.stderr
    args = ("results-page", "results/std", "--thesis", "results/thesis", "--out", "docs/results.md")
    refused = _albot1(
        "results-page", "results/std", "--thesis", "results/std", "--out", "docs/results.md", cwd=tmp_path
    )
    assert refused.returncode == 1 and refused.stderr.strip().splitlines() == [
        "albot1: error: results/std: --thesis expects the results of the 'thesis' suite (`albot1 bench thesis`), "
        "found those of suite 'std'; give its results folder, e.g. results/thesis"
    ]
    done = _albot1(*args, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    data = load_data(tmp_path / "docs" / "results" / "results.json")
    assert data is not None
    rows = {row.method: row for row in data.standard if row.kind == "measured"}
    assert set(rows) == {"odometry", "odometry:sparse-map"}
    ours, taken = rows["odometry"], rows["odometry:sparse-map"]
    assert ours.store == "" and ours.speed is not None and ours.source.startswith("this suite, run ")
    assert taken.store == "results/thesis" and taken.speed is None and taken.source.startswith("results/thesis, run ")
    assert taken.note == f"from results/thesis; {THESIS_SPEED_NOTE}"
    (record,) = (r for r in collect(tmp_path / "results" / "thesis")[1] if r.cell.method_label == "odometry:sparse-map")
    stored = json.loads((record.run_dir / "metrics.json").read_text(encoding="utf-8"))["relations"]
    assert taken.translation_mean_m == stored["translation_m"]["mean"]
    page = (tmp_path / "docs" / "results.md").read_text(encoding="utf-8")
    assert "odometry:sparse-map: from `results/thesis`, whose suite runs them" in page
