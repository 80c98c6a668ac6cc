"""The generalisation page (albot1.report.generalisation): paired ratio to the odometry, bootstrap verdicts."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from albot1.bench.grid import Cell, GridPlan
from albot1.data.model import Frame, Scan, Sequence
from albot1.metrics.record import MetricsRecord
from albot1.records import ResultRecord, read_record
from albot1.report.collect import CellRecord
from albot1.report.generalisation import PERFECT, Comparison, _csv, comparisons, render_page
from albot1.report.tuning import LEGEND, MARK
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run


def _row(method: str, ratio: float, low: float, high: float, verdict: str, held: bool | None) -> Comparison:
    return Comparison(
        "fhw-corrected?odometry=laser-pose",
        method,
        "none",
        1,
        0,
        ratio,
        1.0,
        ratio,
        low,
        high,
        verdict,
        0.2,
        0.1,
        None,
        2.0,
        held,
    )


def test_the_page_lists_where_a_method_is_worse_than_its_odometry_with_marks() -> None:
    plan = GridPlan("generalisation", None, "", [], [], [], {}, [0], ["none"], {})
    rows = [_row("gtsam-graph", 11.0, 9.0, 13.0, "worse", False), _row("albot1:plus", 0.2, 0.1, 0.3, "better", True)]
    text = render_page(plan, rows, ["mrpt-icp on fhw-corrected (none)"])
    assert LEGEND in text
    assert "| gtsam-graph | fhw-corrected?odometry=laser-pose | none | 1 | 11.000 | 1.000 | 11 | 9–13 |" in text
    assert f"| albot1:plus {MARK} | none | 1 | 0.200 | 1.000 | 0.2 [0.1–0.3] | better |" in text
    assert "| gtsam-graph | 1 | 0 | 0 | 0 | 1 | 11 | 11 (fhw-corrected?odometry=laser-pose, none) |" in text
    assert "0.200 / 0.100 (2.00x)" in text and "| n/a |" in text
    assert "| albot1:plus | 1 | 1 | 1 | 0 | 0 | 0.2 |" in text  # its one cell is held-in
    assert "Every seed failed (reasons: the report's README): mrpt-icp on fhw-corrected (none)." in text
    assert "Nowhere" in render_page(plan, rows[1:])


def test_a_worse_ratio_close_to_one_is_printed_with_the_digits_that_show_it_above_one() -> None:
    """At 3 digits the row read ``1 [1–1]`` beside "worse" (and ``1 | 1–1`` in the worse table): no evidence shown."""
    plan = GridPlan("generalisation", None, "", [], [], [], {}, [0], ["none"], {})
    text = render_page(plan, [_row("kiss-icp", 1.0004, 1.0003, 1.0005, "worse", False)])
    assert "| 1.0004 [1.0003–1.0005] | worse |" in text
    assert "| 1.000 | 1.0004 | 1.0003–1.0005 |" in text
    assert "| 0.2 [0.1–0.3] |" in render_page(plan, [_row("m", 0.2, 0.1, 0.3, "better", False)])
    # not significantly above 1: listed as such with the digits that show it above 1 (was "kiss-icp ... 1")
    same = render_page(plan, [_row("kiss-icp", 1.0004, 0.9, 1.1, "indistinguishable", False)])
    assert "Ratio above 1 but not significantly: kiss-icp on fhw-corrected?odometry=laser-pose (none) 1.0004." in same
    tie = render_page(plan, [_row("kiss-icp", 1.0000001, 0.9, 1.1, "indistinguishable", False)])
    assert "Ratio above 1 but not significantly" not in tie  # above 1 by rounding only


def test_names_with_markdown_and_html_characters_are_written_as_text_on_every_line_of_the_page() -> None:
    """A ``|`` in a method's name split its row into one more column; ``<b>`` was HTML; ``*x*`` italic."""
    plan = GridPlan("generalisation", None, "", [], [], [], {}, [0], ["none"], {})
    rows = [_row("a|b <b>*x*", 11.0, 9.0, 13.0, "worse", False)]
    text = render_page(plan, rows, ["m|n on d<1> (none)"])
    name = "a\\|b &lt;b&gt;\\*x\\*"
    assert f"| {name} | fhw-corrected?odometry=laser-pose | none | 1 | 11.000 | 1.000 | 11 | 9–13 |" in text
    assert f"| {name} | 1 | 0 | 0 | 0 | 1 | 11 | 11 (fhw-corrected?odometry=laser-pose, none) |" in text
    assert f"| {name} | none | 1 | 11.000 | 1.000 | 11 [9–13] | worse |" in text
    assert "Every seed failed (reasons: the report's README): m\\|n on d&lt;1&gt; (none)." in text
    assert "<b>" not in text and "a|b" not in text


def test_with_perfect_odometry_the_method_ate_is_shown_without_a_ratio() -> None:
    plan = GridPlan("generalisation", None, "", [], [], [], {}, [0], ["none"], {})
    row = replace(_row("gtsam-graph", 0.0, 0.0, 0.0, PERFECT, False), ate_m=0.126, odometry_ate_m=0.0)
    text = render_page(plan, [row])
    assert "## With perfect odometry" in text
    assert "| gtsam-graph | 0.126 |" in text
    assert f"| gtsam-graph | none | 1 | 0.126 | 0.000 | n/a | {PERFECT} |" in text
    assert "Nowhere" in text  # perfect odometry is not counted as "worse"


def test_scan_dropout_with_exact_odometry_is_a_column_of_its_own_beside_the_undisturbed_run() -> None:
    """Both rows have perfect odometry; the dropout row must not stand in for the undisturbed one."""
    plan = GridPlan("generalisation", None, "", [], [], [], {}, [0], ["none"], {})
    none = replace(_row("gtsam-graph", 0.0, 0.0, 0.0, PERFECT, False), ate_m=0.304, odometry_ate_m=0.0)
    dropout = replace(none, degradation="dropout:0.5", seeds=3, ate_m=0.411)
    text = render_page(plan, [none, dropout])
    log = "fhw-corrected?odometry=laser-pose"
    assert f"| method | {log} | {log} (dropout:0.5) |" in text
    assert "| gtsam-graph | 0.304 | 0.411 |" in text


def _drive(name: str, scans: int = 40) -> Sequence:
    """A straight drive with reference poses; the odometry is 10 % long and turns 0.5 deg per step."""
    t = np.arange(scans, dtype=float)
    truth = np.column_stack([t * 0.5, np.zeros(scans), np.zeros(scans)])
    odometry = np.column_stack([t * 0.55, np.zeros(scans), np.radians(0.5) * t])
    angles = np.radians(np.linspace(-90.0, 90.0, 181))
    frames = [
        Frame(i, Scan(np.full(181, 5.0), angles, 100.0 + t[i], 30.0), odometry[i], reference=truth[i])
        for i in range(scans)
    ]
    return Sequence.from_frames(name, frames)


def _stored(tmp_path: Path, method_label: str, method: str, scans: int = 40) -> CellRecord:
    result = run_method("odometry", _drive("drive", scans), dataset_name="drive")
    run_dir = write_run(result, tmp_path)
    evaluate_run(run_dir)
    cell = Cell("t", "drive", "drive", method, method_label, "default", "none", 0, run_dir.name, "v", 1.0, 1.0)
    metrics = read_record(MetricsRecord, run_dir / "metrics.json")
    return CellRecord(cell, "done", run_dir, read_record(ResultRecord, run_dir / "result.json"), metrics, None)


def test_a_run_whose_poses_are_its_odometry_has_ratio_one_from_its_own_run_folder(tmp_path: Path) -> None:
    """The pair is read from one run folder: poses vs the odometry it was given, both against the reference."""
    same = _stored(tmp_path / "a", "kiss-icp", "kiss-icp")  # an odometry run filed as another method's cell
    odometry = _stored(tmp_path / "b", "odometry", "odometry")
    rows = comparisons([odometry, same])
    assert [(r.method, r.seeds, r.failed) for r in rows] == [("kiss-icp", 1, 0)]  # odometry is not compared
    row = rows[0]
    assert row.ratio == pytest.approx(1.0) and row.ratio_low == pytest.approx(1.0)
    assert row.verdict == "indistinguishable" and row.ate_m == pytest.approx(row.odometry_ate_m) and row.ate_m > 0.1
    assert row.held_in is False  # kiss-icp is not tuned on "drive"


def test_a_run_of_fewer_scans_than_a_paired_comparison_needs_is_n_a_with_the_reason(tmp_path: Path) -> None:
    """6 scans: the project's one paired comparison does not apply (old: a bootstrap over 6 values, a verdict)."""
    rows = comparisons([_stored(tmp_path, "kiss-icp", "kiss-icp", scans=6)])
    row = rows[0]
    assert (row.verdict, row.reason, row.seeds) == ("n/a", "6 pairs, fewer than 10", 1)
    assert math.isnan(row.ratio) and row.ate_m == pytest.approx(row.odometry_ate_m) and row.ate_m > 0.01
    plan = GridPlan("generalisation", None, "", [], [], [], {}, [0], ["none"], {})
    text = render_page(plan, rows)
    assert (
        f"| kiss-icp | none | 1 | {row.ate_m:.3f} | {row.odometry_ate_m:.3f} | n/a | n/a (6 pairs, fewer than 10) |"
        in text
    )
    assert "Not compared (no paired comparison applies): kiss-icp on drive (none): 6 pairs, fewer than 10." in text
    assert "| kiss-icp | 0 |" not in text and "nan" not in text  # not a cell of the per-method counts


def test_the_csv_leaves_a_missing_ratio_empty_and_says_why(tmp_path: Path) -> None:
    """Perfect odometry has no ratio: an empty cell, never "nan" (old: nan,nan,nan)."""
    row = replace(_row("gtsam-graph", math.nan, math.nan, math.nan, PERFECT, False), ate_m=0.126, odometry_ate_m=0.0)
    lines = _csv([row]).splitlines()
    assert lines[0].endswith(",held_in,reason")
    assert lines[1] == (
        "fhw-corrected?odometry=laser-pose,gtsam-graph,none,1,0,0.126,0,,,,perfect odometry,0.2,0.1,,2,False,"
    )


def _seed_run(tmp_path: Path, method_label: str, seed: int, scale: float) -> CellRecord:
    """An odometry run on a 20 m straight drive whose odometry is ``scale`` times long, filed as ``method_label``'s
    cell of ``seed``."""
    t = np.arange(41, dtype=float)
    truth = np.column_stack([t * 0.5, np.zeros(41), np.zeros(41)])
    odometry = np.column_stack([t * 0.5 * scale, np.zeros(41), np.radians(0.5) * t])
    angles = np.radians(np.linspace(-90.0, 90.0, 181))
    frames = [
        Frame(i, Scan(np.full(181, 5.0), angles, 100.0 + t[i], 30.0), odometry[i], reference=truth[i])
        for i in range(41)
    ]
    run_dir = write_run(run_method("odometry", Sequence.from_frames("drive", frames), dataset_name="drive"), tmp_path)
    evaluate_run(run_dir)
    cell = Cell("t", "drive", "drive", method_label, method_label, "default", "none", seed, run_dir.name, "v", 1, 1)
    metrics = read_record(MetricsRecord, run_dir / "metrics.json")
    return CellRecord(cell, "done", run_dir, read_record(ResultRecord, run_dir / "result.json"), metrics, None)


def test_rpe_beside_the_odometry_is_a_mean_over_the_same_seeds(tmp_path: Path) -> None:
    """The odometry cell of seed 1 failed: its mean was over seed 0 alone and the method's over seeds 0 and 1, so
    the ratio beside them compared a good seed with a bad one (3.69x here, where the seed both ran gives 1.00x).
    The loop gap beside its odometry's is paired the same way (one helper)."""
    method = [_seed_run(tmp_path / f"m{seed}", "kiss-icp", seed, scale) for seed, scale in ((0, 1.1), (1, 1.9))]
    odometry = _seed_run(tmp_path / "o0", "odometry", 0, 1.1)  # the same drive as the method's seed 0
    failed = replace(odometry, cell=replace(odometry.cell, seed=1), status="failed", metrics=None)
    (row,) = comparisons([*method, odometry, failed])
    assert row.seeds == 2
    assert row.rpe10_m is not None and row.rpe10_m == pytest.approx(row.odometry_rpe10_m)
    (alone,) = comparisons(method)  # no odometry cell: the method's mean over its own seeds, the odometry's n/a
    assert alone.odometry_rpe10_m is None and alone.rpe10_m is not None and alone.rpe10_m > row.rpe10_m
