"""`albot1 evaluate --trajectory EST --reference REF [--align ...] [--time-offset S]`: the command line."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from albot1.cli import app as app_module
from albot1.cli.app import app
from albot1.cli.evaluate import ALIGN_HELP
from albot1.data.trajectory import write_tum
from albot1.runs.pair import ALIGN_CHOICES

runner = CliRunner()


def error_line(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *args: str) -> str:
    """The console entry point run in-process: its one error line (non-zero exit, no traceback)."""
    monkeypatch.setattr(sys, "argv", ["albot1", *args])
    with pytest.raises(SystemExit) as ended:
        app_module.main()
    err = capsys.readouterr().err
    assert ended.value.code not in (0, None)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


@pytest.fixture
def pair(tmp_path: Path) -> tuple[Path, Path]:
    t = np.arange(100) * 0.1
    ref = np.column_stack([t, np.sin(t), t / 10])
    write_tum(tmp_path / "gt.tum", t, ref)
    write_tum(tmp_path / "est.tum", t[3:] - 0.2, ref[3:] + [0.1, 0.0, 0.0])
    return tmp_path / "est.tum", tmp_path / "gt.tum"


def test_the_summary_says_how_many_reference_poses_had_no_pose(pair: tuple[Path, Path]) -> None:
    est, ref = pair
    args = ["evaluate", "--trajectory", str(est), "--reference", str(ref), "--time-offset", "0.2", "--align", "none"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "97 of 100 reference poses scored, 3 had no pose of the trajectory (time offset 0.2 s, --align none)" in (
        result.stdout
    )
    assert "rmse 0.100 m" in result.stdout
    data = json.loads(runner.invoke(app, [*args, "--json"]).stdout)
    assert data["trajectory"]["reference_without_pose"] == 3 and data["ate"]["alignment"] == "none"


def test_first_n_is_named_in_the_headline(pair: tuple[Path, Path]) -> None:
    est, ref = pair
    args = ["evaluate", "--trajectory", str(est), "--reference", str(ref), "--time-offset", "0.2", "--align", "first:5"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "(rigid alignment on the first 5 pairs)" in result.stdout


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--align", "sideways"], "--align 'sideways' is not understood"),
        (["--time-offset", "nan"], "--time-offset is nan"),
    ],
)
def test_bad_combinations_are_one_line(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    pair: tuple[Path, Path],
    extra: list[str],
    message: str,
) -> None:
    est, ref = pair
    line = error_line(monkeypatch, capsys, "evaluate", "--trajectory", str(est), "--reference", str(ref), *extra)
    assert message in line


def test_dataset_and_reference_together_is_a_usage_error(pair: tuple[Path, Path]) -> None:
    est, ref = pair
    args = ["evaluate", "--trajectory", str(est), "--reference", str(ref), "--dataset", "synthetic-corridor"]
    result = runner.invoke(app, args)
    assert result.exit_code == 2 and "--reference FILE, not both" in " ".join(result.output.split())


def test_a_folder_as_the_trajectory_says_it_is_a_folder(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], pair: tuple[Path, Path]
) -> None:
    est, ref = pair
    line = error_line(monkeypatch, capsys, "evaluate", "--trajectory", str(est.parent), "--reference", str(ref))
    assert line.endswith(f"{est.parent}: is a folder; expected a trajectory file (tum | kitti | carmen)")


def test_the_help_names_every_alignment_choice() -> None:
    for choice in ALIGN_CHOICES:
        assert choice in ALIGN_HELP
