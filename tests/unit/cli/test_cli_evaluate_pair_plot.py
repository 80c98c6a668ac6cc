"""`albot1 evaluate --trajectory EST --reference REF --plot DIR`: the figures are drawn, not silently skipped.

``--plot`` used to be honoured with a run folder or ``--dataset`` only; beside ``--reference`` it was ignored
without a word (no folder, no note), and ``--plot-also`` without ``--plot`` was ignored everywhere.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.data.trajectory import write_tum

runner = CliRunner()


def _files(tmp_path: Path) -> tuple[Path, Path, Path]:
    """A reference arc, the arc 10 % too large, and the arc moved rigidly (zero ATE after alignment)."""
    t = 50.0 + 0.1 * np.arange(80)
    s = 0.2 * np.arange(80)
    truth = np.column_stack([4 * np.sin(s / 4), 4 - 4 * np.cos(s / 4), s / 4])
    written = []
    for name, poses in (("gt", truth), ("big", truth * [1.1, 1.1, 1.0]), ("moved", truth + [2.0, -1.0, 0.0])):
        write_tum(tmp_path / f"{name}.tum", t, poses)
        written.append(tmp_path / f"{name}.tum")
    return written[0], written[1], written[2]


def test_plot_beside_a_reference_file_draws_every_figure(tmp_path: Path) -> None:
    gt, big, moved = _files(tmp_path)
    plots = tmp_path / "plots"
    args = ["evaluate", "--trajectory", str(big), "--reference", str(gt), "--plot", str(plots)]
    result = runner.invoke(app, [*args, "--plot-also", str(moved), "--label", "mine"], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    drawn = sorted(p.name for p in plots.glob("*.png"))
    assert drawn == ["errors.png", "mine-ape.png", "moved-ape.png", "trajectories.png"], result.output
    assert "plots: " in result.stderr


def test_plot_also_without_plot_is_refused_not_ignored(tmp_path: Path) -> None:
    gt, big, moved = _files(tmp_path)
    result = runner.invoke(
        app, ["evaluate", "--trajectory", str(big), "--reference", str(gt), "--plot-also", str(moved)]
    )
    assert result.exit_code == 2
    said = " ".join(result.output.replace("│", " ").split())  # the message as typer boxes it, unwrapped
    assert "--plot-also adds files to the figures of --plot DIR; give --plot DIR too" in said


def test_evo_files_for_one_matched_pose_say_so_not_that_the_reference_has_none(tmp_path: Path) -> None:
    gt, big, _ = _files(tmp_path)
    one = tmp_path / "one.tum"
    one.write_text(big.read_text(encoding="utf-8").splitlines()[1] + "\n", encoding="utf-8")  # line 0: header
    result = runner.invoke(
        app, ["evaluate", "--trajectory", str(one), "--reference", str(gt), "--evo", str(tmp_path / "evo")]
    )
    assert result.exit_code == 0, result.output
    assert "need at least 2 poses scored against reference poses; 1 was" in result.stderr
    assert "the dataset has none" not in result.stderr
