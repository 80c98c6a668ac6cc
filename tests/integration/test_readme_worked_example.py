"""The README's worked example, run as written: own ROS2 bag + reference + another system's TUM -> the report.

The commands come from the README itself (``.ci/readme-example`` prints the
```bash blocks after the ``<!-- worked-example part N`` markers), so the
README and this test cannot drift apart: they are run in an empty folder
with the CLI of this tree, and what the README says they print and the
numbers it quotes are checked against what they did print and write.
"""

from __future__ import annotations

import csv
import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from albot1.data import catalog
from albot1.settings import get_settings

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
EXTRACT = ROOT / ".ci" / "readme-example"
OWN_BAG = "robot.mcap?reference=gt.tum"
EXTERNAL = "mine (external)"

pytestmark = [pytest.mark.integration, pytest.mark.whole_log]


def _needs(*names: str) -> None:
    settings = get_settings()
    missing = [n for n in names if not catalog.is_available(n, settings)]
    if missing:
        pytest.skip(f"dataset(s) {', '.join(missing)} not in ALBOT1_DATA_DIR (the worked example is made from them)")


def _block_after(marker: str) -> list[str]:
    """The lines of the first fenced block after the README line starting with ``marker``."""
    lines = README.read_text(encoding="utf-8").splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(marker))
    body: list[str] = []
    fenced = False
    for line in lines[start + 1 :]:
        if line.startswith("```"):
            if fenced:
                return body
            fenced = True
            continue
        if fenced:
            body.append(line)
        elif line.startswith("|"):  # a table is its own block
            body.append(line)
        elif body:
            return body
    return body


def _table(marker: str) -> dict[str, str]:
    """``first column -> second column`` of the Markdown table after ``marker`` (header rows dropped)."""
    rows = [[cell.strip() for cell in line.strip("|").split("|")] for line in _block_after(marker)]
    return {row[0]: row[1] for row in rows[2:]}


@dataclass(frozen=True)
class Ran:
    folder: Path
    output: str


def _run_part(part: int, folder: Path) -> Ran:
    """Run README part ``part`` in ``folder`` with an ``albot1`` on PATH that is this tree's CLI."""
    script = subprocess.run([str(EXTRACT), str(part), str(README)], capture_output=True, text=True, check=True).stdout
    bindir = folder.parent / "bin"
    bindir.mkdir(exist_ok=True)
    shim = bindir / "albot1"
    shim.write_text(f"#!/bin/sh\nexec {sys.executable} -c 'from albot1.cli.app import main; main()' \"$@\"\n")
    shim.chmod(0o755)
    env = {
        **os.environ,
        "PATH": f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}",
        "PYTHONPATH": str(ROOT),
        "MPLBACKEND": "Agg",
    }
    done = subprocess.run(
        ["bash", "-euo", "pipefail", "-c", script],
        cwd=folder,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, f"README part {part} failed:\n{done.stdout}"
    return Ran(folder, done.stdout)


def _check_printed(part: int, output: str) -> None:
    """Every line of the README's output block is printed (``...`` stands for what differs per machine)."""
    for line in _block_after(f"<!-- worked-example output {part} "):
        for fragment in (f.strip() for f in line.split("...")):
            if fragment:
                assert fragment in output, f"README says part {part} prints {fragment!r}; it printed:\n{output}"


def _three_digits(value: float) -> str:
    return f"{value:.3g}"


@pytest.fixture(scope="module")
def part1(tmp_path_factory: pytest.TempPathFactory) -> Ran:
    _needs("aces-corrected")
    folder = tmp_path_factory.mktemp("readme") / "work"
    folder.mkdir()
    return _run_part(1, folder)


def test_part1_runs_the_baselines_on_the_bag_and_reports_the_external_system(part1: Ran) -> None:
    _check_printed(1, part1.output)
    report = part1.folder / "reports" / "robot"
    for page in ("README.md", "metrics.md", "metrics.csv", "metrics.tex", "cost.md", "generalisation.md", "index.html"):
        assert EXTERNAL in (report / page).read_text(encoding="utf-8"), page
    assert not (report / "standard-benchmark.md").exists()  # no standard log in part 1: no empty page
    suite = (part1.folder / "robot.toml").resolve()  # the pages say how to run it again: by its path
    assert f"`albot1 bench {suite} && albot1 report results/robot`" in (report / "generalisation.md").read_text()
    plots = {p.name for p in (report / "plots").iterdir()}
    for kind in ("trajectories", "ape", "error-distance", "rpe-boxes", "maps"):
        (svg,) = [name for name in plots if name.endswith(f"-{kind}.svg") and name.startswith("robot.mcap")]
        assert EXTERNAL in (report / "plots" / svg).read_text(encoding="utf-8"), svg
    with (report / "cells.csv").open(newline="") as f:
        cells = {row["method"]: row for row in csv.DictReader(f) if row["dataset"] == OWN_BAG}
    assert set(cells) == {"odometry", "kiss-icp", "gtsam-graph", EXTERNAL}
    assert all(row["status"] == "done" for row in cells.values())
    quoted = _table("<!-- worked-example ate 1 ")
    measured = {method: _three_digits(float(row["ate_rmse_m"])) for method, row in cells.items()}
    assert quoted == measured, "the README's ATE table differs from the report's"


def test_part2_puts_the_external_system_on_the_standard_page(part1: Ran) -> None:
    _needs("mit-csail")
    part2 = _run_part(2, part1.folder)
    _check_printed(2, part2.output)
    report = part2.folder / "reports" / "robot"
    page = (report / "standard-benchmark.md").read_text(encoding="utf-8")
    assert re.search(rf"^\| {re.escape(EXTERNAL)} \| measured \|", page, re.MULTILINE), page
    assert "| Cartographer (Hess et al. 2016) | **published** |" in page
    with (report / "standard-benchmark.csv").open(newline="") as f:
        rows = {
            (row["method"] + (" (published)" if row["kind"] == "published" else "")): row
            for row in csv.DictReader(f)
            if row["log"] == "mit-csail" and row["translation_mean_m"]
        }
    quoted = _table("<!-- worked-example standard 2 ")
    assert quoted, "the README quotes no standard-page row"
    for method, value in quoted.items():
        measured = float(rows[method]["translation_mean_m"])
        if method == EXTERNAL:
            # The stand-in is Albot1+ (`--preset plus`), whose degeneracy screen uses the CPU's BLAS: its products
            # round the last bit differently on other CPUs (docs/albot1-mapper.md, the screen kernel), and the map
            # follows; the README's 1.5756 m was measured on an Intel Xeon, an AMD EPYC gives 1.5758 m. 1 mm is five
            # times that difference: a real change of the stand-in's output by millimetres still fails here.
            assert measured == pytest.approx(float(value), abs=1e-3), method
        else:
            assert f"{measured:.4f}" == value, method
    assert EXTERNAL in quoted
    assert (report / "plots" / "mit-csail-relation-boxes.svg").read_text(encoding="utf-8").count(EXTERNAL) >= 1
