"""`albot1 bench` and `albot1 report` from the command line: dry run, defaults, errors as one line."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from typer.testing import CliRunner

from albot1.cli.app import app


def test_dry_run_lists_the_planned_cells_without_running_them(tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["bench", "quick", "--dry-run", "--results", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert "suite quick:" in result.output and "synthetic-office-startstop" in result.output
    assert not any(tmp_path.iterdir())


def test_errors_are_one_line_on_stderr_with_exit_1(tmp_path: Path) -> None:
    for args, words in (
        (["report", str(tmp_path)], "no grid.json"),
        (["bench", "no-such-suite"], "no suite named 'no-such-suite'"),
        (["bench", "quick", "--executor", "ray"], "executor 'ray' not understood"),
    ):
        done = subprocess.run(
            [sys.executable, "-c", "from albot1.cli.app import main; main()", *args],
            capture_output=True,
            text=True,
            cwd=tmp_path,
            timeout=120,
        )
        assert done.returncode == 1, done.stderr
        assert done.stderr.startswith("albot1: error: ") and words in done.stderr
        assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1


def test_bench_exits_1_after_the_whole_grid_when_a_cell_failed(tmp_path: Path) -> None:
    suite = tmp_path / "onefails.toml"
    suite.write_text(
        '[[methods]]\nname = "odometry"\n\n'
        '[[methods]]\nname = "odometry"\nlabel = "odometry:bad-config"\nset = { map_voxel_m = -1 }\n\n'
        '[[datasets]]\nname = "synthetic-office-startstop"\n'
    )
    done = subprocess.run(
        [sys.executable, "-c", "from albot1.cli.app import main; main()", "bench", str(suite), "-j", "1"]
        + ["--results", str(tmp_path / "results"), "--no-progress"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert done.returncode == 1, done.stderr
    assert "total" in done.stdout and "albot1 report" in done.stdout  # the summary was printed first
    assert done.stderr.strip().splitlines()[-1] == "1 of 2 cells failed (reasons above and in the report)"
    assert "Traceback" not in done.stderr
    assert (tmp_path / "results" / "onefails" / "grid.json").is_file()
