"""The metrics tables' paired comparisons (albot1.report.paired_tables): against the reference and the best."""

from __future__ import annotations

import csv
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from albot1.bench.grid import Cell
from albot1.data.model import Frame, Scan, Sequence
from albot1.metrics.paired import BETTER, PERFECT_REFERENCE, SAME, WORSE
from albot1.metrics.record import MetricsRecord
from albot1.records import ResultRecord, read_record
from albot1.report.collect import CellRecord
from albot1.report.comparisons import Errors, all_pairs
from albot1.report.paired_tables import (
    NO_DECISION,
    NO_ERRORS,
    NO_EVIDENCE,
    TABLE,
    error_kind,
    markdown_lines,
    no_pairs,
    paired_rows,
)
from albot1.report.tables import write_tables
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

SCANS = 40


def _drive(error: float, scans: int = SCANS) -> Sequence:
    """A straight drive with reference poses; the odometry is ``error`` too long and turns ``error`` deg per step."""
    t = np.arange(scans, dtype=float)
    truth = np.column_stack([t * 0.5, np.zeros(scans), np.zeros(scans)])
    odometry = np.column_stack([t * 0.5 * (1 + error), np.zeros(scans), np.radians(error) * t])
    angles = np.radians(np.linspace(-90.0, 90.0, 181))
    frames = [
        Frame(i, Scan(np.full(181, 5.0), angles, 100.0 + t[i], 30.0), odometry[i], reference=truth[i])
        for i in range(scans)
    ]
    return Sequence.from_frames("drive", frames)


def _record(tmp_path: Path, method: str, error: float, seed: int, scans: int = SCANS) -> CellRecord:
    """An odometry run of the drive filed as ``method``'s cell of seed ``seed`` (its poses: that odometry)."""
    sequence = _drive(error, scans)
    run_dir = write_run(run_method("odometry", sequence, dataset_name="drive"), tmp_path / f"{method}-{seed}")
    evaluate_run(run_dir)
    key = f"{method}-{seed}"  # unique per cell, as in a suite
    cell = Cell("t", "drive", "drive", method, method, "default", "gauss:0.1:1", seed, key, "v", 1.0, 1.0)
    metrics = read_record(MetricsRecord, run_dir / "metrics.json")
    return CellRecord(cell, "done", run_dir, read_record(ResultRecord, run_dir / "result.json"), metrics, None)


@pytest.fixture(scope="module")
def records(tmp_path_factory: pytest.TempPathFactory) -> list[CellRecord]:
    root = tmp_path_factory.mktemp("paired")
    out = []
    for seed in (0, 1):
        out += [
            _record(root, "odometry", 0.10, seed),
            _record(root, "kiss-icp", 0.02, seed),  # a known better method: a fifth of the odometry's error
            _record(root, "gtsam-graph", 0.10, seed),  # the odometry's errors exactly
        ]
    return out


def test_a_better_method_is_better_an_identical_one_indistinguishable(records: list[CellRecord]) -> None:
    rows = {r.method: r for r in paired_rows(records)}
    assert {(r.reference, r.best, r.kind, r.runs) for r in rows.values()} == {("odometry", "kiss-icp", "position", 2)}
    good, odo, twin = rows["kiss-icp"], rows["odometry"], rows["gtsam-graph"]
    assert good.against_best is None and odo.against_reference is None  # each is the other's reference point
    assert good.against_reference is not None and good.against_reference.verdict == BETTER
    assert (good.against_reference.pairs, good.against_reference.groups) == (2 * SCANS, 2)  # seeds pooled as strata
    assert good.against_reference.high < 0.5
    assert twin.against_reference is not None
    found = twin.against_reference
    assert (found.verdict, found.ratio, found.low, found.high) == (SAME, 1.0, 1.0, 1.0)
    assert odo.against_best is not None and odo.against_best.verdict == WORSE
    assert odo.against_best.ratio == pytest.approx(1.0 / good.against_reference.ratio)
    assert paired_rows(records) == paired_rows(records)  # seeded: the same page every time


def test_runs_without_a_partner_seed_are_not_compared_and_say_why(records: list[CellRecord]) -> None:
    alone = [r for r in records if not (r.cell.method == "kiss-icp" and r.cell.seed == 0)]
    alone = [r for r in alone if not (r.cell.method == "odometry" and r.cell.seed == 1)]
    rows = {r.method: r for r in paired_rows(alone)}
    found = rows["kiss-icp"].against_reference
    assert found is not None and (found.verdict, found.reason) == ("n/a", "no run of both on the same data")
    assert paired_rows([r for r in records if r.cell.method == "odometry"]) == []  # one method: nothing to compare


def test_the_tables_show_the_comparison_with_its_test_and_write_the_csv(
    records: list[CellRecord], tmp_path: Path
) -> None:
    lines = markdown_lines(paired_rows(records), "drive")
    assert lines[0] == "Paired comparison, ATE (ratio of RMSEs over the paired scans):"
    assert "| odometry | gauss:0.1:1 | 80 (2) | reference | worse " in "\n".join(lines)
    assert "| gtsam-graph | gauss:0.1:1 | 80 (2) | indistinguishable 1 [1–1] (odometry) | worse " in "\n".join(lines)
    written = write_tables(records, tmp_path)
    text = written["metrics.md"].read_text()
    assert "**Paired comparisons**" in text and "paired moving-block bootstrap (2000 resamples" in text
    assert "**Paired comparisons**" not in written["cost.md"].read_text()
    with written["paired.csv"].open() as f:
        rows = list(csv.DictReader(f))
    assert written["paired.csv"].name == TABLE
    assert [(r["method"], r["against"], r["role"], r["verdict"], r["pairs"]) for r in rows] == [
        ("odometry", "kiss-icp", "best", WORSE, "80"),
        ("kiss-icp", "odometry", "reference", BETTER, "80"),
        ("gtsam-graph", "odometry", "reference", SAME, "80"),
        ("gtsam-graph", "kiss-icp", "best", WORSE, "80"),
    ]


def test_the_error_is_the_ate_with_reference_poses_else_none(records: list[CellRecord]) -> None:
    assert error_kind(records) == "position"
    assert error_kind([CellRecord(records[0].cell, "failed", records[0].run_dir, None, None, None)]) is None


def test_with_perfect_odometry_the_best_is_the_best_imperfect_method(tmp_path: Path) -> None:
    records = [_record(tmp_path, "odometry", 0.0, 0), _record(tmp_path, "kiss-icp", 0.02, 0)]
    records.append(_record(tmp_path, "gtsam-graph", 0.10, 0))
    rows = {r.method: r for r in paired_rows(records)}
    assert {r.best for r in rows.values()} == {"kiss-icp"}
    found = rows["kiss-icp"].against_reference
    assert found is not None and found.reason == PERFECT_REFERENCE  # no ratio to a perfect odometry
    against = rows["gtsam-graph"].against_best
    assert against is not None and against.verdict == WORSE and against.ratio == pytest.approx(5.0, rel=0.05)


def test_a_method_never_paired_with_another_is_not_called_the_best(records: list[CellRecord], tmp_path: Path) -> None:
    # kiss-icp has the lowest pooled error but only seed 0, every other method only seed 1: no pair at all.
    apart = [r for r in records if (r.cell.method == "kiss-icp") == (r.cell.seed == 0)]
    rows = {r.method: r for r in paired_rows(apart)}
    assert rows["kiss-icp"].best == "kiss-icp"
    own = rows["kiss-icp"].against_best
    assert own is not None and (own.verdict, own.reason) == ("n/a", NO_EVIDENCE)
    lines = markdown_lines(list(rows.values()), "drive")
    assert "| kiss-icp | gauss:0.1:1 | – | n/a (odometry) | n/a |" in lines
    assert f"- n/a: {NO_EVIDENCE}: kiss-icp as the best (gauss:0.1:1)" in lines
    assert all("| best |" not in line for line in lines)


def test_with_no_errors_to_read_back_no_method_is_the_best(records: list[CellRecord], tmp_path: Path) -> None:
    """Runs of one degradation without an ATE: nothing to rank, so every 'against the best' is n/a."""
    unreadable = []
    for rec in records:
        if rec.cell.seed == 0 and rec.metrics is not None:
            metrics = rec.metrics.model_copy(update={"ate": None, "ate_reason": "hand-made: no ATE"})
            cell = replace(rec.cell, degradation="dropout:0.5")
            unreadable.append(CellRecord(cell, "done", rec.run_dir, rec.result, metrics, None))
    rows = [r for r in paired_rows(records + unreadable) if r.degradation == "dropout:0.5"]
    assert [(r.method, r.best) for r in rows] == [("odometry", None), ("kiss-icp", None), ("gtsam-graph", None)]
    assert {(r.against_best.verdict, r.against_best.reason) for r in rows if r.against_best is not None} == {
        ("n/a", NO_ERRORS)
    }
    assert all(r.against_best is not None for r in rows)
    lines = markdown_lines(rows, "drive")
    assert lines[4:7] == [
        "| odometry | dropout:0.5 | – | reference | n/a |",
        "| kiss-icp | dropout:0.5 | – | n/a (odometry) | n/a |",
        "| gtsam-graph | dropout:0.5 | – | n/a (odometry) | n/a |",
    ]
    note = f"- n/a: {NO_ERRORS}: odometry against best (dropout:0.5); kiss-icp against best (dropout:0.5); "
    assert f"{note}gtsam-graph against best (dropout:0.5)" in lines


def test_a_store_of_one_method_says_there_is_no_paired_comparison(records: list[CellRecord], tmp_path: Path) -> None:
    """An empty paired.csv used to come with no word on the page: it read as a comparison that found nothing."""
    written = write_tables([r for r in records if r.cell.method == "odometry"], tmp_path)
    text = written["metrics.md"].read_text()
    assert no_pairs() in text and "Paired comparison, " not in text
    assert no_pairs() not in written["cost.md"].read_text()
    assert written["paired.csv"].read_text().count("\n") == 1  # its header only
    assert no_pairs() not in write_tables(records, tmp_path / "all")["metrics.md"].read_text()


@pytest.mark.parametrize("order", [("noisy", "perfect"), ("perfect", "noisy")])
def test_a_perfect_method_is_better_in_the_matrix_whichever_label_comes_first(order: tuple[str, str]) -> None:
    """Old code mirrored "noisy vs perfect: n/a (perfect reference)" into "perfect vs noisy: –" (n/a)."""
    keys = np.arange(20, dtype=np.int64)
    errors = {
        "noisy": Errors(keys, {"position": np.linspace(0.1, 0.5, 20)}),
        "perfect": Errors(keys, {"position": np.zeros(20)}),
    }
    found = all_pairs(list(order), errors, ["position"])
    ahead, behind = found[("perfect", "noisy")][0], found[("noisy", "perfect")][0]
    assert (ahead.verdict, ahead.ratio, ahead.low, ahead.high, ahead.short()) == (BETTER, 0.0, 0.0, 0.0, "< 0")
    assert (behind.verdict, behind.reason, behind.short()) == ("n/a", PERFECT_REFERENCE, "–")


def test_a_best_paired_too_few_times_says_so_not_that_it_was_never_compared(tmp_path: Path) -> None:
    # Three-scan runs (`NAME[:3]`) pair, but 3 pairs are too few for the test: the best's own n/a used to say
    # "no run of another method could be compared with its runs", which was false.
    records = [_record(tmp_path, "odometry", 0.10, 0, scans=3), _record(tmp_path, "kiss-icp", 0.02, 0, scans=3)]
    rows = {r.method: r for r in paired_rows(records)}
    assert rows["kiss-icp"].best == "kiss-icp"
    own = rows["kiss-icp"].against_best
    assert own is not None and (own.verdict, own.reason) == ("n/a", f"{NO_DECISION} (3 pairs, fewer than 10)")
    lines = markdown_lines(list(rows.values()), "drive")
    assert f"- n/a: {NO_DECISION} (3 pairs, fewer than 10): kiss-icp as the best (gauss:0.1:1)" in lines
    assert all(NO_EVIDENCE not in line for line in lines)
