"""Plots ready for a paper: one APE colour scale per figure, runs named in titles, tiny routes visible, medians."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from albot1.bench.grid import Cell
from albot1.data.model import Frame, Scan, Sequence
from albot1.geometry import se2
from albot1.report import trajectory_plots
from albot1.report.collect import CellRecord
from albot1.report.cost_plots import median_window, running_median
from albot1.report.plots import method_colors
from albot1.report.trajectory_plots import plot_ape_map, plot_trajectories, run_tag
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import read_result, write_run

ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 9)


def _records(tmp_path: Path, runs: list[tuple[str, str, int, float]]) -> list[CellRecord]:
    """Odometry 'methods' on a 20 m route; ``scale`` shrinks the poses (1e-4: a run that barely moves)."""
    n = 30
    truth = se2.integrate_steps(np.zeros(3), np.tile([[20.0 / (n - 1), 0.0, np.radians(4.0)]], (n - 1, 1)))
    out = []
    for label, degradation, seed, scale in runs:
        odometry = truth * np.array([scale, scale, 1.0])
        frames = [Frame(i, Scan(np.full(9, 1.0), ANGLES, 10.0 + i, 5.0), odometry[i], truth[i]) for i in range(n)]
        run_dir = write_run(
            run_method("odometry", Sequence.from_frames(label, frames), degradation=degradation, seed=seed), tmp_path
        )
        cell = Cell("t", "w", "w", "odometry", label, "default", degradation, seed, f"{label}{seed}", "v", 1, 1)
        out.append(CellRecord(cell, "done", run_dir, read_result(run_dir), evaluate_run(run_dir), None))
    return out


def _capture(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    figures: list[Any] = []

    def keep(fig: Any, path: Path) -> Path:
        figures.append(fig)
        return path

    monkeypatch.setattr(trajectory_plots, "save", keep)
    return figures


def test_ape_panels_share_one_colour_scale_stated_on_the_bar(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from matplotlib.collections import LineCollection

    records = _records(tmp_path, [("good", "none", 0, 1.0), ("bad", "gauss:0.2:2", 3, 1.0)])
    figures = _capture(monkeypatch)
    plot_ape_map(records, "w", tmp_path / "a.png", method_colors(["good", "bad"]))
    (fig,) = figures
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert len(panels) == 2
    limits = [c.get_clim() for ax in panels for c in ax.collections if isinstance(c, LineCollection)]
    worst = max(float(rec.metrics.ate.max_m) for rec in records if rec.metrics and rec.metrics.ate)  # type: ignore[union-attr]
    assert len(limits) == 2 and all(
        lim == (0.0, pytest.approx(worst, rel=1e-9)) for lim in limits
    )  # one scale, up to the worst pose of any panel
    bars = [ax for ax in fig.axes if ax.get_ylabel().startswith("APE (m)")]
    assert len(bars) == 1 and bars[0].get_ylabel() == f"APE (m), one scale for all panels: 0 to {worst:.3g} m"
    titles = [ax.get_title() for ax in panels]
    assert titles[0].startswith("good [none, seed 0]: ") and titles[1].startswith("bad [gauss:0.2:2, seed 3]: ")


def test_a_route_that_barely_moves_is_circled_and_says_how_far_it_moves(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    records = _records(tmp_path, [("moves", "none", 0, 1.0), ("stuck", "none", 0, 1e-4)])
    figures = _capture(monkeypatch)
    plot_trajectories(records, "w", tmp_path / "t.png", method_colors(["moves", "stuck"]))
    (fig,) = figures
    lines = {line.get_label(): line for line in fig.axes[0].get_lines()}
    stuck_label = next(name for name in lines if name.startswith("stuck"))
    assert set(lines) == {"reference", "moves [none, seed 0]", stuck_label}
    stuck = lines[stuck_label]
    span = float(np.ptp(stuck.get_xydata(), axis=0).max())
    assert 1e-4 < span < 3e-3 and stuck_label == f"stuck [none, seed 0] (moves {span:.2g} m: circled)"
    assert stuck.get_marker() == "o" and stuck.get_markevery() == [0, 29]
    assert lines["moves [none, seed 0]"].get_marker() in ("None", "", None)


def test_run_tag_and_running_median_window() -> None:
    cell = Cell("t", "w", "w", "odometry", "m", "default", "thesis", 2, "k", "v", 1, 1)
    assert run_tag(CellRecord(cell, "done", Path("/x"), None, None, None)) == "[thesis, seed 2]"
    assert [median_window(n) for n in (1, 5, 80, 900, 5000)] == [1, 5, 9, 9, 50]
    spiky = np.array([1.0] * 20)
    spiky[[3, 11]] = 100.0
    assert running_median(spiky, median_window(len(spiky))).tolist() == [1.0] * 20  # spikes gone, unlike raw data


def test_relation_boxes_hold_each_relation_error_and_the_published_marks(tmp_path: Path) -> None:
    from albot1.data.model import Relations
    from albot1.methods.baselines.published import published_systems
    from albot1.report.relation_plots import plot_relation_boxes, published_marks, relation_error_sets

    n = 20
    truth = se2.integrate_steps(np.zeros(3), np.tile([[0.5, 0.0, np.radians(5.0)]], (n - 1, 1)))
    stamps = 10.0 + np.arange(n)
    i1, i2 = np.arange(0, n - 5), np.arange(5, n)
    # every relation is the true motion followed by 0.1 m forward and 2 deg: the error is exactly that, inverted
    rel = se2.compose(se2.between(truth[i1], truth[i2]), np.array([0.1, 0.0, np.radians(2.0)]))
    relations = Relations(stamps[i1], stamps[i2], rel)
    frames = [Frame(i, Scan(np.full(9, 1.0), ANGLES, stamps[i], 5.0), truth[i], truth[i]) for i in range(n)]
    run_dir = write_run(run_method("odometry", Sequence.from_frames("r", frames, relations=relations)), tmp_path)
    cell = Cell("t", "aces", "aces", "odometry", "odometry", "default", "none", 0, "k", "v", 1, 1)
    records = [CellRecord(cell, "done", run_dir, read_result(run_dir), evaluate_run(run_dir), None)]
    ((label, (tag, trans, rot)),) = relation_error_sets(records).items()
    assert (label, tag, len(trans)) == ("odometry", "[none, seed 0]", n - 5)
    assert trans == pytest.approx(np.full(n - 5, 0.1), abs=1e-8)  # relations.txt stores them to ~1e-9
    assert rot == pytest.approx(np.full(n - 5, 2.0), abs=1e-6)
    expected = sorted(
        (s.label, f.mean) for s in published_systems() for f in s.figures
        if f.log == "aces" and f.metric == "relation_translation_m"
    )  # fmt: skip
    assert sorted((name, mean) for name, mean, _ in published_marks("aces")["relation_translation_m"]) == expected
    assert len(expected) >= 4 and published_marks("aces[:500]") == {
        "relation_translation_m": [],
        "relation_rotation_deg": [],
    }
    assert plot_relation_boxes(records, "aces", tmp_path / "r.png", {"odometry": "#7f7f7f"}) == tmp_path / "r.png"
    assert "published" in (tmp_path / "r.svg").read_text()


def test_a_floor_note_naming_many_series_is_counted_and_does_not_collapse_the_layout(tmp_path: Path) -> None:
    import warnings

    from albot1.report.plots import pyplot, save, value_axis

    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(8.0, 4.0), layout="constrained")
    labels = [f"method-with-a-long-name-{i}" for i in range(8)]
    for ax in axes:
        ax.boxplot([np.array([1e-4, 0.1, 1.0])] * 8, positions=range(8))
        value_axis(ax, 0.0023, labels, "m")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # matplotlib warns when constrained layout collapses an axes
        warnings.simplefilter("ignore", ResourceWarning)  # another test's garbage, freed here by chance
        save(fig, tmp_path / "f.png")
    svg = (tmp_path / "f.svg").read_text()
    assert "(8 series)" in svg and "method-with-a-long-name-0" not in svg
    fig, ax = plt.subplots(layout="constrained")
    value_axis(ax, 0.01, ["a", "b"], "deg")
    assert [t.get_text() for t in ax.texts] == ["values below 0.01 deg drawn at 0.01 (a, b)"]
    plt.close(fig)
