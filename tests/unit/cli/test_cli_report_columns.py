"""`albot1 report --columns`: the selection reaches the tables; a wrong key is one line before anything is written.

The error case runs the real entry point (``albot1.cli.app.main``) in a
child process, so the one-line error handling of ``main`` is what is checked.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from albot1.bench.grid import GridPlan
from albot1.bench.store import ResultsStore
from albot1.cli.app import app
from albot1.report.collect import COST_COLUMNS, METRIC_COLUMNS

runner = CliRunner()


def _store(tmp_path: Path) -> Path:
    store = ResultsStore(tmp_path / "results" / "empty")
    store.runs.mkdir(parents=True)
    store.write_plan(GridPlan("empty", None, "", [], [], [], {}, [], [], {}))
    return store.root


@pytest.mark.slow
def test_the_selection_reaches_every_table(tmp_path: Path) -> None:
    out = tmp_path / "report"
    done = runner.invoke(app, ["report", str(_store(tmp_path)), "--out", str(out), "--columns", "relation_m,total_s"])
    assert done.exit_code == 0, done.output
    metrics = (out / "metrics.md").read_text(encoding="utf-8")
    # Markdown escapes the option's underscores (shown the same); the HTML page writes them as they are.
    shown = r"Columns shown (--columns relation\_m,total\_s): relation trans. (m). Hidden here and in metrics.csv"
    assert shown in metrics
    cost = (out / "cost.md").read_text(encoding="utf-8")
    assert r"Columns shown (--columns relation\_m,total\_s): total (s). " in cost
    assert "Columns shown (--columns relation_m,total_s)" in (out / "index.html").read_text(encoding="utf-8")


@pytest.mark.slow
def test_an_unknown_key_is_one_line_with_the_closest_and_every_valid_key(tmp_path: Path) -> None:
    out = tmp_path / "report"
    command = [sys.executable, "-c", "from albot1.cli.app import main; main()"]
    command += ["report", str(_store(tmp_path)), "--out", str(out), "--columns", "ate_rmse_m,loopgap_m"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120, env=dict(os.environ))
    assert done.returncode == 1 and done.stdout == "" and "Traceback" not in done.stderr
    keys = ", ".join({**METRIC_COLUMNS, **COST_COLUMNS})
    assert done.stderr == (
        f"albot1: error: --columns: unknown column key 'loopgap_m' (did you mean 'loop_gap_m'?); valid keys: {keys}\n"
    )
    assert not out.exists()  # refused before the report folder was made


def test_report_help_names_the_option() -> None:
    text = runner.invoke(app, ["report", "--help"], env={"COLUMNS": "140"}).stdout
    assert "--columns" in text and "KEY,KEY,...: the number columns" in text
