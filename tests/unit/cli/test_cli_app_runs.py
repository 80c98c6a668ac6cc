"""`albot1 --version`, the dataset reference syntax in `--help`, `albot1 runs` and the `latest` link."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from albot1 import __version__
from albot1.cli.app import app
from albot1.versions import code_version, commit_label, git_commit

runner = CliRunner()


def test_version_prints_the_package_version_and_the_code_digest() -> None:
    done = runner.invoke(app, ["--version"])
    expected = f"albot1 {__version__} (code {code_version()}, {commit_label(git_commit())})"
    assert done.exit_code == 0 and done.stdout.strip() == expected


def test_help_documents_the_dataset_reference_syntax() -> None:
    text = runner.invoke(app, ["--help"], env={"COLUMNS": "150"}).stdout
    for form in ("NAME[:N]", "NAME?key=value", "odometry=reference", "views=D_M:A_DEG"):
        assert form in text, form
    assert "NAME[:N]" in runner.invoke(app, ["run", "--help"], env={"COLUMNS": "150"}).stdout


def test_runs_lists_the_run_folders_and_marks_the_latest(tmp_path: Path) -> None:
    for limit in ("20", "30"):
        done = runner.invoke(app, ["run", "odometry", "synthetic-corridor", "--limit", limit, "--out", str(tmp_path)])
        assert done.exit_code == 0, done.output
        assert done.stderr == ""  # no progress bar when stderr is not a terminal
    listing = json.loads(runner.invoke(app, ["runs", str(tmp_path), "--json"]).stdout)
    assert len(listing["runs"]) == 2 and {r["status"] for r in listing["runs"]} == {"done"}
    latest = [r for r in listing["runs"] if r["latest"]]
    assert len(latest) == 1 and (tmp_path / "latest").resolve().name == latest[0]["key"]
    text = runner.invoke(app, ["runs", str(tmp_path)]).stdout
    assert "odometry:default on synthetic-corridor[:30] [none, seed 0], 30 scans <- latest" in text
    assert text.strip().endswith(f"2 run folders in {tmp_path}")


def test_every_spelling_of_one_slice_is_one_run_folder_under_the_canonical_name(tmp_path: Path) -> None:
    """``[0:30]``, ``[:30:1]``, ``[:030]``, ``[::1][:30]`` and ``--limit 30`` are the scans of ``[:30]``: one run,
    so one key and one folder, recorded as ``synthetic-corridor[:30]`` (a suite's cells already share it)."""
    spellings = [
        ["synthetic-corridor[:30]"],
        ["synthetic-corridor[0:30]"],
        ["synthetic-corridor[:30:1]"],
        ["synthetic-corridor[:030]"],
        ["synthetic-corridor[::1][:30]"],
        ["synthetic-corridor", "--limit", "30"],
    ]
    summaries = []
    for spelling in spellings:
        done = runner.invoke(app, ["run", "odometry", *spelling, "--out", str(tmp_path), "--json"])
        assert done.exit_code == 0, done.output
        summaries.append(json.loads(done.stdout))
    assert {s["run_dir"] for s in summaries} == {summaries[0]["run_dir"]}
    assert {s["dataset"] for s in summaries} == {"synthetic-corridor[:30]"}
    assert len([p for p in tmp_path.iterdir() if p.name != "latest"]) == 1


def test_python_dash_m_albot1_runs_the_command_line(tmp_path: Path) -> None:
    """A checkout used through PYTHONPATH has no `albot1` script on PATH; `python -m albot1` is the way in, and
    it used to fail with "albot1 is a package and cannot be directly executed"."""
    import os
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[3]
    env = {**os.environ, "PYTHONPATH": str(root)}
    command = [sys.executable, "-m", "albot1"]
    done = subprocess.run([*command, "--help"], capture_output=True, text=True, timeout=120, cwd=tmp_path, env=env)
    assert done.returncode == 0 and "Usage: python -m albot1" in done.stdout, done.stderr
    missing = str(tmp_path / "none.clf")
    done = subprocess.run(
        [*command, "datasets", "info", missing], capture_output=True, text=True, timeout=120, cwd=tmp_path, env=env
    )
    assert done.returncode == 1 and done.stderr.startswith("albot1: error: ") and "Traceback" not in done.stderr
