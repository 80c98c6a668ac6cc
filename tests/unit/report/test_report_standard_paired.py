"""The standard page's paired comparisons: every two measured methods on the same relations, bootstrap verdicts."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from albot1.bench.grid import Cell, GridPlan
from albot1.data.model import Frame, Relations, Scan, Sequence
from albot1.geometry import se2
from albot1.metrics.paired import BETTER, PERFECT_REFERENCE, SAME, WORSE
from albot1.metrics.record import MetricsRecord
from albot1.records import ResultRecord, read_record
from albot1.report.collect import CellRecord
from albot1.report.comparisons import NOT_REPRODUCED, relation_errors_of
from albot1.report.standard import PAIRED_TABLE, paired_by_log, write_standard
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

ANGLES = np.radians(np.linspace(-90.0, 90.0, 181))
SCANS = 30


def _sequence(stretch: float) -> Sequence:
    """A straight drive, odometry ``stretch`` too long; 29 relations between successive scans (0.5 m each)."""
    t = np.arange(SCANS, dtype=float)
    truth = np.column_stack([t * 0.5, np.zeros(SCANS), np.zeros(SCANS)])
    odometry = np.column_stack([t * 0.5 * (1 + stretch), np.zeros(SCANS), np.zeros(SCANS)])
    frames = [Frame(i, Scan(np.full(181, 5.0), ANGLES, 100.0 + t[i], 30.0), odometry[i]) for i in range(SCANS)]
    i1, i2 = np.arange(SCANS - 1), np.arange(1, SCANS)
    relations = Relations(t1=100.0 + t[i1], t2=100.0 + t[i2], poses=se2.between(truth[i1], truth[i2]))
    return Sequence.from_frames("straight", frames, relations=relations)


def _record(tmp_path: Path, method: str, stretch: float) -> CellRecord:
    """An odometry run of the drive filed as ``method``'s whole-log cell on aces (its poses: the odometry)."""
    run_dir = write_run(run_method("odometry", _sequence(stretch), dataset_name="straight"), tmp_path / method)
    evaluate_run(run_dir)
    cell = Cell("t", "aces", "aces", method, method, "default", "none", 0, run_dir.name, "v", 60.0, 1024.0)
    metrics = read_record(MetricsRecord, run_dir / "metrics.json")
    return CellRecord(cell, "done", run_dir, read_record(ResultRecord, run_dir / "result.json"), metrics, None)


def test_a_method_with_half_the_error_is_better_an_identical_one_indistinguishable(tmp_path: Path) -> None:
    odometry = _record(tmp_path, "odometry", 0.10)  # 0.05 m per relation
    good = _record(tmp_path, "kiss-icp", 0.05)  # 0.025 m per relation
    twin = _record(tmp_path, "gtsam-graph", 0.10)  # the odometry's errors exactly
    paired = paired_by_log([odometry, good, twin])["aces"]
    assert paired.labels == ["odometry", "kiss-icp", "gtsam-graph"] and paired.left_out == {}
    trans, rot = paired.found[("kiss-icp", "odometry")]
    assert (trans.verdict, trans.pairs, trans.groups) == (BETTER, SCANS - 1, 1)
    assert trans.ratio == pytest.approx(0.5) and trans.low == pytest.approx(0.5) and trans.high == pytest.approx(0.5)
    assert rot.verdict == "n/a" and rot.reason == PERFECT_REFERENCE  # no rotation error
    back = paired.found[("odometry", "kiss-icp")][0]
    assert back.verdict == WORSE and back.ratio == pytest.approx(2.0)
    same = paired.found[("gtsam-graph", "odometry")][0]
    assert (same.verdict, same.ratio, same.low, same.high) == (SAME, 1.0, 1.0, 1.0)


def test_the_page_shows_a_matrix_per_log_and_the_csv_every_interval(tmp_path: Path) -> None:
    records = [_record(tmp_path, "odometry", 0.10), _record(tmp_path, "kiss-icp", 0.05)]
    out = tmp_path / "report"
    out.mkdir()
    plan = GridPlan("t", None, "", [], [], [], {}, [0], ["none"], {})
    text = write_standard(plan, records, out)[0].read_text()
    assert "paired moving-block bootstrap (2000 resamples" in text
    assert "| row vs column | odometry | kiss-icp |" in text
    assert "| odometry | · | > 2 / – |" in text and "| kiss-icp | < 0.5 / – | · |" in text
    assert f"- `–` {PERFECT_REFERENCE}: odometry vs kiss-icp (rotation)" in text  # each n/a with its reason
    with (out / PAIRED_TABLE).open() as f:
        rows = list(csv.DictReader(f))
    assert [(r["method"], r["against"], r["error"], r["verdict"], r["relations"]) for r in rows] == [
        ("odometry", "kiss-icp", "translation", WORSE, "29"),
        ("odometry", "kiss-icp", "rotation", "n/a", "29"),
    ]
    assert float(rows[0]["ratio"]) == pytest.approx(2.0)
    assert rows[1]["reason"] == PERFECT_REFERENCE


def test_a_run_folder_that_does_not_reproduce_its_metric_is_left_out_with_the_reason(tmp_path: Path) -> None:
    rec = _record(tmp_path, "odometry", 0.10)
    other = _record(tmp_path, "kiss-icp", 0.05)
    poses = rec.stored_run().poses
    poses[:, 0] *= 1.5  # the folder's poses no longer those metrics.json was computed from
    assert relation_errors_of(rec).missing == NOT_REPRODUCED
    paired = paired_by_log([rec, other])["aces"]
    assert paired.labels == ["kiss-icp"] and paired.left_out == {"odometry": NOT_REPRODUCED}
    failed = CellRecord(other.cell, "failed", tmp_path, None, None, None)
    assert paired_by_log([failed])["aces"].labels == []


def test_the_matrix_and_its_csv_mark_a_method_tuned_on_the_log(tmp_path: Path) -> None:
    """gtsam-graph's [tuned_on] lists aces: "gtsam-graph < odometry" there is a fit, and the page says so."""
    records = [_record(tmp_path, "odometry", 0.10), _record(tmp_path, "gtsam-graph", 0.05)]
    records.append(_record(tmp_path, "my-plugin", 0.05))  # no [tuned_on]: unknown, not held-out
    out = tmp_path / "report"
    out.mkdir()
    plan = GridPlan("t", None, "", [], [], [], {}, [0], ["none"], {})
    text = write_standard(plan, records, out)[0].read_text()
    assert "| row vs column | odometry | gtsam-graph † | my-plugin |" in text
    assert "| gtsam-graph † | < 0.5 / – | · |" in text
    with (out / PAIRED_TABLE).open() as f:
        rows = [r for r in csv.DictReader(f) if r["error"] == "translation"]
    held = {(r["method"], r["against"]): (r["held_in"], r["against_held_in"]) for r in rows}
    assert held == {
        ("odometry", "gtsam-graph"): ("False", "True"),
        ("odometry", "my-plugin"): ("False", ""),
        ("gtsam-graph", "my-plugin"): ("True", ""),
    }
