"""`albot1 run` and `albot1 evaluate RUN_DIR` say when their numbers are held-in, as the pages' mark does.

A method whose ``[tuned_on]`` lists the run's dataset printed its counts, timings and metrics with no word that
they were measured on data its values were chosen on; a trajectory file (an external system) says nothing,
since its tuning is unknown, not "none".
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.report import tuning
from albot1.report.tuning import MARK

runner = CliRunner()
WORLD = "synthetic-corridor"


def invoke(*args: str) -> str:
    result = runner.invoke(app, list(args), catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.stdout


@pytest.fixture
def odometry_tuned_on_the_corridor(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """odometry's preset recorded as tuned on :data:`WORLD` (every other method on nothing)."""

    def tuned(owner: Any, preset: str) -> tuple[str, ...]:
        return (WORLD,) if owner.name == "odometry" else ()

    monkeypatch.setattr(tuning, "tuned_on", tuned)
    tuning.tuned_datasets.cache_clear()
    yield
    tuning.tuned_datasets.cache_clear()


def test_run_and_evaluate_say_a_held_in_number_is_one(odometry_tuned_on_the_corridor: None, tmp_path: Path) -> None:
    out = str(tmp_path / "runs")
    lines = invoke("run", "odometry", WORLD, "--limit", "30", "--out", out).splitlines()
    assert len(lines) == 2 and lines[1].startswith(f"{MARK} held-in: odometry:default was tuned on this data")
    assert f"({WORLD}; the [tuned_on] table of " in lines[1] and "odometry.toml" in lines[1]
    summary = json.loads(invoke("run", "odometry", WORLD, "--limit", "30", "--out", out, "--json"))
    assert summary["held_in"] is True
    shown = invoke("evaluate", summary["run_dir"]).splitlines()
    assert shown[-1].strip().startswith(f"{MARK} held-in: odometry:default") and "odometry.toml" in shown[-1]
    # the same poses as another system's file: unknown tuning, nothing said (not "held-out" either)
    trajectory = Path(summary["run_dir"]) / "trajectory.tum"
    scored = invoke("evaluate", "--trajectory", str(trajectory), "--dataset", f"{WORLD}[:30]", "--label", "odometry")
    assert "held-in" not in scored and MARK not in scored


def test_a_held_out_run_prints_no_mark(tmp_path: Path) -> None:
    tuning.tuned_datasets.cache_clear()
    out = str(tmp_path / "runs")
    lines = invoke("run", "odometry", WORLD, "--limit", "30", "--out", out).splitlines()
    assert len(lines) == 1 and MARK not in lines[0]
    summary = json.loads(invoke("run", "odometry", WORLD, "--limit", "30", "--out", out, "--json"))
    assert summary["held_in"] is False
    assert MARK not in invoke("evaluate", summary["run_dir"])
