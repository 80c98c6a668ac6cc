"""`albot1 bench --dry-run` checks the options the run would refuse (out49's suite sweep)."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.errors import Albot1Error

SUITE = (
    '[grid]\ndegradations = []\nundegraded_seeds = [0]\n[[methods]]\nname = "odometry"\n'
    '[[datasets]]\nname = "synthetic-corridor"\nlimit = 5\n'
)


@pytest.mark.parametrize(
    ("option", "says"),
    [
        (["-j", "0"], "-j 0: expected at least one parallel job"),
        (["-j", "-1"], "-j -1: expected at least one parallel job"),
        (["--executor", "ray"], "executor 'ray' not understood; expected local | dask | dask://HOST:PORT"),
    ],
)
def test_a_dry_run_refuses_what_the_run_would(tmp_path: Path, option: list[str], says: str) -> None:
    """Old code: exit 0 with the planned cells, then the real command with the same options failed."""
    suite = tmp_path / "tiny.toml"
    suite.write_text(SUITE)
    result = CliRunner().invoke(app, ["bench", str(suite), "--dry-run", "--results", str(tmp_path / "r"), *option])
    # main() prints an Albot1Error as the one line "albot1: error: <message>", exit 1
    assert isinstance(result.exception, Albot1Error) and str(result.exception) == says, result.output
    assert "suite tiny" not in result.output
    assert not (tmp_path / "r").exists()


def test_a_dry_run_with_good_options_still_plans(tmp_path: Path) -> None:
    suite = tmp_path / "tiny.toml"
    suite.write_text(SUITE)
    result = CliRunner().invoke(app, ["bench", str(suite), "--dry-run", "-j", "3", "--executor", "dask://h:1"])
    assert result.exit_code == 0, result.output
    assert "suite tiny: 1 cells" in result.output
