"""`albot1 evaluate --plot DIR`: error-coloured trajectory, error over time and distance, several trajectories."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.data.open import open_sequence
from albot1.data.trajectory import write_tum
from albot1.metrics.ate import position_errors
from albot1.report import evaluate_plots
from albot1.report.evaluate_plots import plot_scored
from albot1.runs.scored import Scored

N = 25


def _scored(name: str, offset: float, reference: bool = True) -> Scored:
    t = 100.0 + np.arange(N) * 0.5
    truth = np.column_stack([np.arange(N) * 0.4, np.zeros(N), np.zeros(N)])
    poses = truth.copy()
    poses[:, 1] += offset * np.arange(N) / (N - 1)  # drifts sideways up to ``offset`` m
    return Scored(
        header={"method": name},
        dataset="toy",
        timestamps=t,
        poses=poses,
        reference=truth if reference else None,
        relations=None,
        relations_source="",
        relation_timestamps=t,
        relation_poses=poses,
    )


def test_figures_share_one_scale_and_plot_the_ate_errors(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    figures: dict[str, Any] = {}

    def keep(fig: Any, path: Path) -> Path:
        figures[path.name] = fig
        return path

    monkeypatch.setattr(evaluate_plots, "save", keep)
    drawn = plot_scored([_scored("mine", 0.5), _scored("theirs", 1.0)], tmp_path)
    assert [p.name for p in drawn.files] == ["trajectories.png", "mine-ape.png", "theirs-ape.png", "errors.png"]
    assert drawn.missing is None
    bars = [
        ax for name in ("mine-ape.png", "theirs-ape.png") for ax in figures[name].axes if ax.get_label() == "<colorbar>"
    ]
    assert len(bars) == 2 and len({bar.get_ylim() for bar in bars}) == 1  # one scale for every figure of a call
    by_time, by_distance = figures["errors.png"].axes[:2]
    (mine, theirs) = by_time.get_lines()
    assert mine.get_xdata().tolist() == pytest.approx((np.arange(N) * 0.5).tolist())
    assert by_distance.get_lines()[0].get_xdata().tolist() == pytest.approx((np.arange(N) * 0.4).tolist())
    # the lines are the per-pose errors whose RMSE is the ATE
    other = _scored("theirs", 1.0)
    assert other.reference is not None
    expected = position_errors(other.poses, other.reference, "rigid")
    assert theirs.get_ydata().tolist() == pytest.approx(np.asarray(expected).tolist(), abs=1e-15)
    assert max(theirs.get_ydata()) > max(mine.get_ydata()) > 0  # more drift, more error left after the alignment
    assert {line.get_label() for line in figures["trajectories.png"].axes[0].get_lines()} == {
        "reference",
        "mine",
        "theirs",
    }


def test_without_reference_only_the_trajectories_are_drawn(tmp_path: Path) -> None:
    drawn = plot_scored([_scored("mine", 0.5, reference=False)], tmp_path)
    assert [p.name for p in drawn.files] == ["trajectories.png"]
    assert drawn.missing == "the dataset has no reference poses: no error figures"
    assert (tmp_path / "trajectories.svg").is_file()


@pytest.mark.slow
def test_cli_plot_writes_the_figures(tmp_path: Path) -> None:
    arrays = open_sequence("synthetic-office-loop[:40]").arrays
    assert arrays.reference is not None
    write_tum(tmp_path / "est.tum", arrays.timestamps, arrays.reference + [0.05, 0.0, 0.0])
    write_tum(tmp_path / "other.tum", arrays.timestamps, arrays.odometry)
    result = CliRunner().invoke(
        app,
        ["evaluate", "--trajectory", str(tmp_path / "est.tum"), "--dataset", "synthetic-office-loop[:40]"]
        + ["--plot", str(tmp_path / "plots"), "--plot-also", str(tmp_path / "other.tum")],
    )
    assert result.exit_code == 0, result.output
    names = sorted(p.name for p in (tmp_path / "plots").iterdir())
    assert names == sorted(
        f"{stem}.{ext}" for stem in ("trajectories", "est-ape", "other-ape", "errors") for ext in ("png", "svg")
    )
