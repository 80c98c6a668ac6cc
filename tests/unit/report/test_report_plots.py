"""Report plots on tiny runs: shapes follow the data, one colour per method, PNG and SVG, honest axes."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from albot1.bench.grid import Cell
from albot1.data.model import Frame, Scan, Sequence
from albot1.geometry import se2
from albot1.metrics.record import MetricsRecord
from albot1.report.collect import METRIC_COLUMNS, CellRecord, severity_order
from albot1.report.cost_plots import plot_scan_time
from albot1.report.html import CAPTIONS
from albot1.report.map_plots import occupancy, plot_maps
from albot1.report.plots import (
    FIXED_COLORS,
    PALETTE,
    SLUG_CHARS,
    Extent,
    log_floor,
    method_colors,
    panel_layout,
    representative,
    slug,
)
from albot1.report.robustness_plots import plot_robustness
from albot1.report.rpe_plots import plot_rpe_boxes, segment_error_sets
from albot1.report.tables import aggregate, cells_frame
from albot1.report.trajectory_plots import plot_ape_map, plot_error_vs_distance, plot_trajectories
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import read_result, write_run

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 9)


def test_severity_order_puts_none_first_then_gaussian_by_sigma_then_thesis() -> None:
    levels = ["thesis", "gauss:0.2:3", "none", "bias:0.01:0.1", "gauss:0.05:0.5", "gauss:0.1:1"]
    assert severity_order(levels) == ["none", "gauss:0.05:0.5", "gauss:0.1:1", "gauss:0.2:3", "bias:0.01:0.1", "thesis"]


def test_severity_order_ranks_biases_by_size_whatever_their_sign() -> None:
    """A signed order put ``bias:-0.05:-1`` before ``bias:0.01:0.1``, as if it were the milder one."""
    assert severity_order(["bias:-0.05:-1", "bias:0.01:0.1", "none", "bias:0.05:1"]) == [
        "none",
        "bias:0.01:0.1",
        "bias:-0.05:-1",
        "bias:0.05:1",
    ]


def test_slug_makes_dataset_labels_file_safe() -> None:
    assert slug("aces") == "aces" and slug("synthetic-office-loop") == "synthetic-office-loop"
    assert re.fullmatch(r"aces_2500_2-h[0-9a-f]{10}", slug("aces[:2500:2]"))
    assert re.fullmatch(r"data_my_log.clf-h[0-9a-f]{10}", slug("/data/my log.clf"))


def test_slugs_are_unique_and_short_for_every_label() -> None:
    labels = ["büro", "båro", "b_ro", "b ro", "aces[:2500:2]", "aces_2500_2", "/x/" + "a" * 290 + ".clf", ".", "..", ""]
    labels.append(slug("aces[:2500:2]"))  # a label that looks like a hashed slug is hashed too
    slugs = [slug(label) for label in labels]
    assert len(set(slugs)) == len(labels)
    for name in slugs:
        assert len(name) <= SLUG_CHARS + 12 and re.fullmatch(r"[A-Za-z0-9_.-]+", name)
        assert not name.startswith(".")


def _cell(method: str, degradation: str, seed: int, dataset: str = "w") -> Cell:
    return Cell(
        suite="t",
        dataset=dataset,
        dataset_label=dataset,
        method="odometry",
        method_label=method,
        preset="default",
        degradation=degradation,
        seed=seed,
        key=f"{method}{degradation}{seed}",
        code_version="v",
        time_s=1,
        memory_mb=1,
    )


def _stub(method: str, degradation: str, seed: int, status: str = "done") -> CellRecord:
    return CellRecord(_cell(method, degradation, seed), status, Path("/x"), None, None, None)


def test_representative_run_is_the_undegraded_lowest_seed_that_completed() -> None:
    records = [
        _stub("a", "gauss:0.1:1", 0),
        _stub("a", "none", 1),
        _stub("a", "none", 0, status="failed"),
        _stub("b", "gauss:0.1:1", 2),
        _stub("b", "gauss:0.1:1", 1),
    ]
    chosen = representative(records)
    assert (chosen["a"].cell.degradation, chosen["a"].cell.seed) == ("none", 1)
    assert (chosen["b"].cell.degradation, chosen["b"].cell.seed) == ("gauss:0.1:1", 1)


def test_one_colour_per_method_name_whatever_else_the_report_holds() -> None:
    colors = method_colors(["odometry", "albot1", "odometry", "kiss-icp"])
    assert colors == {"odometry": "#7f7f7f", "albot1": "#1f77b4", "kiss-icp": "#ff7f0e"}
    assert method_colors(["kiss-icp"])["kiss-icp"] == "#ff7f0e"  # not from its place among the others
    assert len(set(FIXED_COLORS.values())) == len(FIXED_COLORS)
    other = method_colors(["cartographer (external)"])["cartographer (external)"]
    assert other in PALETTE
    assert method_colors(["albot1", "cartographer (external)", "x"])["cartographer (external)"] == other


def test_panels_follow_the_data_aspect_ratio() -> None:
    corridor = Extent.around([np.array([[0.0, 0.0], [60.0, 2.0]])])
    assert corridor.aspect == pytest.approx(6.0)  # 60 x 2 m padded to the widest drawn shape, not a strip
    rows, cols, (width, height) = panel_layout(corridor, 5)
    assert (rows, cols) == (5, 1) and width > 12  # long panels stacked, as wide as the page
    square = Extent.around([np.array([[0.0, 0.0], [20.0, 20.0]])])
    rows, cols, (width, height) = panel_layout(square, 4)
    assert (rows, cols) == (2, 2) and 0.6 < width / height < 1.5


def test_a_log_axis_starts_near_the_data_not_at_a_perfect_odometry_1e_10() -> None:
    assert log_floor([[0.08, 0.2, 0.5]]) is None  # one decade: a linear axis
    floor = log_floor([[1e-10, 0.07, 0.9], [36.0]])
    assert floor is not None and 1e-3 < floor < 0.07  # the 1e-10 point is drawn at the floor, not stretched to
    assert log_floor([[0.0, 0.0]]) is None


def test_occupancy_marks_the_cells_that_hold_points() -> None:
    extent = Extent(0.0, 35.0, 0.0, 17.5)
    image, cell = occupancy(np.array([[0.01, 0.01], [34.99, 17.49], [0.02, 0.02]]), extent)
    assert cell == pytest.approx(0.1)  # 35 m over 350 cells
    assert image.shape == (175, 350) and int(image.count()) == 2  # two distinct cells, rows = y
    assert not np.ma.is_masked(image[0, 0]) and not np.ma.is_masked(image[-1, -1])


def _world(length_m: float, turn_deg: float, n: int = 60) -> Sequence:
    """A route of ``n`` scans: straight (a corridor) or turning ``turn_deg`` per step (a loop), walls 1 m away."""
    step = length_m / (n - 1)
    truth = se2.integrate_steps(np.zeros(3), np.tile([[step, 0.0, np.radians(turn_deg)]], (n - 1, 1)))
    frames = [Frame(i, Scan(np.full(len(ANGLES), 1.0), ANGLES, 10.0 + i, 5.0), truth[i], truth[i]) for i in range(n)]
    return Sequence.from_frames("toy", frames)


def _records(tmp_path: Path, sequence: Sequence, dataset: str) -> list[CellRecord]:
    """Two 'methods': dead reckoning on clean odometry, and the same on biased odometry over two seeds."""
    out = []
    for label, degradation, seed in (
        ("clean", "none", 0),
        ("noisy", "gauss:0.05:1", 0),
        ("noisy", "gauss:0.05:1", 1),
        ("biased", "bias:0.01:0.5", 0),
    ):
        run_dir = write_run(run_method("odometry", sequence, degradation=degradation, seed=seed), tmp_path)
        metrics: MetricsRecord = evaluate_run(run_dir)
        cell = _cell(label, degradation, seed, dataset)
        out.append(CellRecord(cell, "done", run_dir, read_result(run_dir), metrics, None))
    return out


@pytest.fixture(scope="module")
def corridor(tmp_path_factory: pytest.TempPathFactory) -> list[CellRecord]:
    """Runs on a 40 m straight route (a corridor), shared by the tests of this module (they only read them)."""
    return _records(tmp_path_factory.mktemp("corridor"), _world(40.0, 0.0), "corridor")


def _check_png(path: Path | None) -> tuple[int, int]:
    assert path is not None and path.read_bytes()[:8] == PNG_SIGNATURE
    assert path.with_suffix(".svg").read_text().startswith("<?xml")  # the vector twin
    from matplotlib.image import imread  # here, not at collection: matplotlib costs every test run's collection

    pixels = imread(path)
    assert float(pixels[..., :3].std()) > 0.05  # not a blank canvas
    return pixels.shape[1], pixels.shape[0]


@pytest.mark.slow
def test_every_plot_of_a_corridor_is_wide_png_and_svg(tmp_path: Path, corridor: list[CellRecord]) -> None:
    records = corridor
    colors = method_colors(r.cell.method_label for r in records)
    out = tmp_path / "plots"
    out.mkdir()
    width, height = _check_png(plot_trajectories(records, "corridor", out / "t.png", colors))
    assert width > 2 * height  # a 40 m corridor is drawn wide, not as a strip in a square
    width, height = _check_png(plot_maps(records, "corridor", out / "m.png", colors))
    assert width > height / 2  # three wide panels stacked
    _check_png(plot_ape_map(records, "corridor", out / "a.png", colors))
    _check_png(plot_error_vs_distance(records, "corridor", out / "e.png", colors))
    _check_png(plot_rpe_boxes(records, "corridor", out / "r.png", colors))
    _check_png(plot_scan_time(records, "corridor", out / "s.png", colors))
    legend_text = (out / "t.svg").read_text()
    assert all(label in legend_text for label in ("clean", "noisy", "biased", "reference"))


def test_rpe_boxes_use_every_segment_length_the_route_is_long_enough_for(corridor: list[CellRecord]) -> None:
    lengths, errors = segment_error_sets(corridor)
    assert lengths == [1.0, 2.0, 5.0, 10.0, 20.0]  # 50 and 100 m are beyond a 40 m route
    assert set(errors) == {"clean", "noisy", "biased"}
    assert float(np.abs(errors["clean"][0]).max()) == pytest.approx(0.0, abs=1e-6)  # clean odometry: no error
    # 20 m segments start at the first scan at or beyond each of metres 0..19 (scans are 0.678 m apart: the
    # one for metre 20 is at 20.3 m, so its segment would end beyond the route)
    assert len(errors["clean"][-1]) == 20


def test_robustness_puts_degradations_on_categories_with_the_spread_of_seeds(tmp_path: Path) -> None:
    records = _records(tmp_path, _world(40.0, 6.0), "loop")
    table = aggregate(cells_frame(records), METRIC_COLUMNS)
    colors = method_colors(r.cell.method_label for r in records)
    _check_png(plot_robustness(table, "loop", "ate_rmse_m", "ATE RMSE (m)", tmp_path / "rob.png", colors))
    svg = (tmp_path / "rob.svg").read_text()
    assert ">none<" in svg and ">gauss:0.05:1<" in svg and ">bias:0.01:0.5<" in svg  # one slot per degradation
    assert "drawn at" not in svg  # 0 and ~0.9 m: a linear axis from zero
    # a 1e-10 m ATE beside errors from 0.05 to 36 m: a log axis from near the data, the 1e-10 drawn at its floor
    clean, noisy = table["method"] == "clean", table["method"] == "noisy"
    table.loc[clean, ["ate_rmse_m_mean", "ate_rmse_m_min", "ate_rmse_m_max"]] = 1e-10
    table.loc[noisy, ["ate_rmse_m_mean", "ate_rmse_m_std", "ate_rmse_m_min", "ate_rmse_m_max"]] = [
        36.0,
        4.0,
        33.0,
        39.0,
    ]
    table.loc[table["method"] == "biased", ["ate_rmse_m_mean", "ate_rmse_m_min", "ate_rmse_m_max"]] = 0.05
    plot_robustness(table, "loop", "ate_rmse_m", "ATE RMSE (m)", tmp_path / "log.png", colors)
    svg = (tmp_path / "log.svg").read_text()
    assert "drawn at" in svg and "(clean)" in svg


def test_robustness_says_perturbation_not_odometry_degradation_when_a_level_leaves_the_odometry_alone(
    tmp_path: Path,
) -> None:
    """A scan dropout thins the scans and keeps their odometry: the generalisation suite's figures put
    ``dropout:0.5`` and ``offset:...`` on an axis "odometry degradation (applied to the dataset's odometry ...)"."""
    records = _records(tmp_path, _world(40.0, 6.0), "loop")
    table = aggregate(cells_frame(records), METRIC_COLUMNS)
    colors = method_colors(r.cell.method_label for r in records)
    plot_robustness(table, "loop", "ate_rmse_m", "ATE RMSE (m)", tmp_path / "odometry.png", colors)
    svg = (tmp_path / "odometry.svg").read_text()
    assert "per odometry degradation" in svg and "(applied to the dataset's odometry before" in svg
    table.loc[table["degradation"] == "bias:0.01:0.5", "degradation"] = "dropout:0.5"
    plot_robustness(table, "loop", "ate_rmse_m", "ATE RMSE (m)", tmp_path / "dropout.png", colors)
    svg = (tmp_path / "dropout.svg").read_text()
    assert ">dropout:0.5<" in svg and "odometry degradation" not in svg
    assert "per perturbation" in svg and "perturbation (odometry noise, scan dropout; applied to the data" in svg
    # the page's caption of these figures says so too
    assert all("scan dropout" in CAPTIONS[f"robustness-{kind}"] for kind in ("ate", "drift", "loop-gap"))


def test_trajectory_error_plots_need_a_reference(tmp_path: Path) -> None:
    sequence = _world(10.0, 0.0, n=12)
    frames = [Frame(f.index, f.scan, f.odometry, None) for f in sequence.frames()]
    records = _records(tmp_path, Sequence.from_frames("toy", frames), "no-ref")
    colors = method_colors(r.cell.method_label for r in records)
    assert plot_ape_map(records, "no-ref", tmp_path / "a.png", colors) is None
    assert plot_error_vs_distance(records, "no-ref", tmp_path / "e.png", colors) is None
    assert plot_rpe_boxes(records, "no-ref", tmp_path / "r.png", colors) is None
    _check_png(plot_trajectories(records, "no-ref", tmp_path / "t.png", colors))  # each in its own frame
    assert "own frame" in (tmp_path / "t.svg").read_text()
