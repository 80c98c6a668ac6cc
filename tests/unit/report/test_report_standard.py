"""The standard-benchmark page: measured rows from run folders, published rows from the data file, never mixed."""

from __future__ import annotations

import csv
from dataclasses import replace
from pathlib import Path

import numpy as np

from albot1.bench.grid import Cell, GridPlan, Skipped
from albot1.bench.store import Failure
from albot1.config.presets import load_known_limits
from albot1.data.model import Frame, Relations, Scan, Sequence
from albot1.geometry import se2
from albot1.methods.baselines.published import published_systems
from albot1.metrics.measures.relations import METRIC as RELATIONS
from albot1.metrics.record import MetricsRecord
from albot1.records import ResultRecord, read_record
from albot1.report.collect import CellRecord
from albot1.report.standard import PAGE, STANDARD_LOGS, TABLE, measured_rows, published_rows, write_standard
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

ANGLES = np.radians(np.linspace(-90.0, 90.0, 181))


def _sequence() -> Sequence:
    """A straight 20-scan drive, 1 s apart, odometry 10 % long; relations from the truth (exact values below)."""
    t = np.arange(20, dtype=float)
    truth = np.column_stack([t * 0.5, np.zeros(20), np.zeros(20)])
    odometry = np.column_stack([t * 0.55, np.zeros(20), np.zeros(20)])
    frames = [Frame(i, Scan(np.full(181, 5.0), ANGLES, 100.0 + t[i], 30.0), odometry[i]) for i in range(20)]
    pairs = np.array([[0, 1], [0, 2], [3, 19]])  # 0.5, 1 and 8 m long
    relations = Relations(
        t1=100.0 + t[pairs[:, 0]], t2=100.0 + t[pairs[:, 1]], poses=se2.between(truth[pairs[:, 0]], truth[pairs[:, 1]])
    )
    return Sequence.from_frames("straight", frames, relations=relations)


def _cell(log: str, method: str, key: str, limit: int | None = None) -> Cell:
    return Cell(
        suite="t",
        dataset=log,
        dataset_label=log if limit is None else f"{log}[:{limit}]",
        method=method,
        method_label=method,
        preset="default",
        degradation="none",
        seed=0,
        key=key,
        code_version="v",
        time_s=60.0,
        memory_mb=1024.0,
        limit=limit,
    )


def _plan(skipped: list[Skipped]) -> GridPlan:
    machine = {"cpu_model": "Test CPU 3.0 GHz", "cpu_count": 2, "cpu_count_physical": 1, "memory_gb": 4.0}
    return GridPlan("t", None, "", [], skipped, [], {}, [0], ["none"], {**machine, "platform": "test"})


def _record(tmp_path: Path, log: str, limit: int | None = None) -> CellRecord:
    result = run_method("odometry", _sequence(), dataset_name="straight")
    run_dir = write_run(result, tmp_path)
    evaluate_run(run_dir)
    return CellRecord(
        _cell(log, "odometry", run_dir.name, limit),
        "done",
        run_dir,
        read_record(ResultRecord, run_dir / "result.json"),
        read_record(MetricsRecord, run_dir / "metrics.json"),
        None,
    )


def test_measured_rows_take_the_relation_metric_of_whole_log_runs_only(tmp_path: Path) -> None:
    full = _record(tmp_path, "intel")
    prefix = _record(tmp_path / "p", "intel", limit=10)
    other = _record(tmp_path / "o", "intel-corrected")
    rows = measured_rows([prefix, other, full])
    assert [(r.log, r.kind, r.method) for r in rows] == [("intel", "measured", "odometry")]
    row = rows[0]
    # Odometry 10 % long: errors 0.05, 0.1 and 0.8 m; the longest relation spans 16 s, so none is a loop relation.
    assert row.relations == 3
    np.testing.assert_allclose(row.translation_mean_m, (0.05 + 0.1 + 0.8) / 3)
    np.testing.assert_allclose(row.translation_max_m, 0.8)
    assert row.loop_relations == 0
    assert row.duration_s == 19.0
    assert row.time_s is not None and row.speed == 19.0 / row.time_s
    assert row.cpu_s is not None and row.cpu_s > 0 and row.cpu_speed == 19.0 / row.cpu_s


def test_published_rows_come_from_the_data_file_labelled_with_their_source() -> None:
    rows = published_rows({"aces": 1366.0})
    by = {(r.log, r.method): r for r in rows}
    carto = by[("aces", "Cartographer (Hess et al. 2016)")]
    assert (carto.kind, carto.translation_mean_m, carto.rotation_mean_deg, carto.time_s) == (
        "published",
        0.0375,
        0.373,
        41,
    )
    assert carto.speed == 1366.0 / 41 and "Table II" in carto.source
    gm = by[("mit-csail", "GM (Kuemmerle et al. 2009)")]
    assert (gm.translation_mean_m, gm.translation_std_m) == (0.004, 0.009)
    sm = by[("fr-clinic", "SM (Kuemmerle et al. 2009)")]
    assert sm.rotation_mean_deg is None and "unconfirmed" in sm.note
    assert ("aces", "Graph FLIRT (as quoted by Hess et al. 2016)") not in by  # Hess's Table III has no ACES
    systems = {s.label for s in published_systems()}
    assert {r.method for r in rows} <= systems


def test_the_page_and_csv_keep_measured_and_published_rows_apart(tmp_path: Path) -> None:
    rec = _record(tmp_path / "runs", "aces")
    out = tmp_path / "report"
    out.mkdir()
    plan = _plan([Skipped("fr-clinic", "not found under the data roots", "albot1 datasets fetch fr-clinic")])
    page, table = write_standard(plan, [rec], out)
    assert (page.name, table.name) == (PAGE, TABLE)
    text = page.read_text()
    assert "Test CPU 3.0 GHz, 2 logical CPUs (1 physical)" in text
    assert "Intel Xeon E5-1650" in text
    assert "Not measured: not found under the data roots (`albot1 datasets fetch fr-clinic`)" in text
    # errors 0.05, 0.1 and 0.8 m: mean ± std, then the median (the typical relation), max, N; rotation 0
    assert "| odometry | measured | 0.3167 ± 0.4193 | 0.1000 | 0.800 | 3 | 0.000 ± 0.000 | 0.000 | 0.00 |" in text
    assert "| Cartographer (Hess et al. 2016) | **published** | 0.0375 ± 0.0426 | n/a | n/a | n/a |" in text
    with table.open() as f:
        rows = list(csv.DictReader(f))
    kinds = {(r["log"], r["kind"]) for r in rows}
    assert ("aces", "measured") in kinds and ("aces", "published") in kinds
    assert {r["log"] for r in rows} <= set(STANDARD_LOGS)
    measured = [r for r in rows if r["kind"] == "measured"]
    assert len(measured) == 1 and measured[0]["source"].startswith("this suite, run ")


def test_a_failed_method_a_method_left_out_of_a_log_and_unrun_systems_are_said_so(tmp_path: Path) -> None:
    aces, intel = _record(tmp_path / "a", "aces"), _record(tmp_path / "i", "intel")
    reason = "mrpt-rbpf: rbpf-slam diverged at scan 2651: the estimate jumped 21.30 m"
    failed = CellRecord(
        _cell("aces", "mrpt-rbpf", "k1"), "failed", tmp_path, None, None, Failure(reason, "exception", 1, 9.0, None)
    )
    rows = measured_rows([aces, intel, failed])
    by = {(r.log, r.method): r for r in rows}
    assert by[("aces", "mrpt-rbpf")].status == "failed" and by[("aces", "mrpt-rbpf")].note == reason
    left_out = by[("intel", "mrpt-rbpf")]
    assert left_out.status == "not measured" and "not in this suite's grid for this log" in left_out.note
    assert ("mit-csail", "mrpt-rbpf") not in by  # no method ran on mit-csail: the log itself says not measured
    out = tmp_path / "report"
    out.mkdir()
    plan = _plan([])
    plan.skipped_methods.append(Skipped("mrpt-icp", "unavailable: needs icp-slam", "make mrpt"))
    text = write_standard(plan, [aces, intel, failed], out)[0].read_text()
    assert f"| mrpt-rbpf † | measured | **failed**: {reason} |" in text  # held-in: its thresholds were set on aces
    assert "† measured on a dataset this method's values were chosen on" in text
    assert "| mrpt-rbpf | failed | not measured | – | – | – |" in text  # the summary table's row
    assert "Methods not run on this machine: mrpt-icp (unavailable: needs icp-slam; `make mrpt`)." in text
    assert "- DP-SLAM: no published figure on these logs." in text


def test_a_failed_or_unrun_row_carries_the_known_limit_its_preset_file_records(tmp_path: Path) -> None:
    limits = load_known_limits("mrpt-rbpf")
    assert limits is not None and set(limits["default"]) == {"aces", "intel", "fr-clinic"}
    aces, clinic = _record(tmp_path / "a", "aces"), _record(tmp_path / "c", "fr-clinic")
    failed = CellRecord(
        _cell("aces", "mrpt-rbpf", "k1"), "failed", tmp_path, None, None, Failure("diverged", "exception", 1, 9.0, None)
    )
    by = {(r.log, r.method): r for r in measured_rows([aces, clinic, failed])}
    assert by[("aces", "mrpt-rbpf")].limit == limits["default"]["aces"]
    assert by[("fr-clinic", "mrpt-rbpf")].status == "not measured"
    assert by[("fr-clinic", "mrpt-rbpf")].limit == limits["default"]["fr-clinic"]
    assert by[("aces", "odometry")].limit == ""  # a done row, and a file without [known_limits]
    out = tmp_path / "report"
    out.mkdir()
    text = write_standard(_plan([]), [aces, clinic, failed], out)[0].read_text()
    line = f"- mrpt-rbpf (failed), known limit from its preset file: {limits['default']['aces']}"
    assert line in text.splitlines()
    assert f"- mrpt-rbpf (not measured), known limit from its preset file: {limits['default']['fr-clinic']}" in text


def test_several_seeds_show_the_lowest_completed_one_and_name_the_others(tmp_path: Path) -> None:
    """With seeds run in any order, the row is the lowest completed seed's, and its note says what the others gave.

    The row used to be whichever record came first: here seed 2's, or the failed seed 0 hiding two completed ones.
    """
    one = _replace_seed(_record(tmp_path / "1", "aces"), 1)
    two = _replace_seed(_record(tmp_path / "2", "aces"), 2)
    failed = CellRecord(
        _cell("aces", "odometry", "k-0"), "failed", tmp_path, None, None, Failure("boom", "exception", 1, 9.0, None)
    )
    assert one.metrics is not None
    block = one.metrics.get(RELATIONS)
    assert block is not None
    mean = block.translation_m.mean
    for order in ([two, failed, one], [failed, one, two], [one, two, failed]):
        (row,) = [r for r in measured_rows(order) if r.log == "aces"]
        assert row.status == "done" and row.translation_mean_m == mean
        assert row.note == f"seed 1 shown (the lowest completed) of 3 seeds run; seed 0 failed, seed 2 {mean:.4f} m"
    (alone,) = [r for r in measured_rows([failed]) if r.log == "aces"]
    assert alone.status == "failed" and alone.note == "boom"  # one seed: as before, no seeds note
    (none_done,) = measured_rows([_replace_seed(failed, 3), failed])
    assert none_done.note == "boom; seed 0 shown (none completed) of 2 seeds run; seed 3 failed"


def _replace_seed(rec: CellRecord, seed: int) -> CellRecord:
    return replace(rec, cell=replace(rec.cell, seed=seed, key=f"k-{seed}"))


def test_the_paired_matrix_compares_the_seed_the_row_shows(tmp_path: Path) -> None:
    """A failed seed 0 listed first left the method out of the matrix although its row showed a completed seed."""
    from albot1.report.standard_paired import compare_by_log

    odometry = _record(tmp_path / "o", "aces")
    other = _replace_seed(_record(tmp_path / "x", "aces"), 1)
    other = CellRecord(
        replace(other.cell, method="kiss-icp", method_label="kiss-icp"),
        "done",
        other.run_dir,
        other.result,
        other.metrics,
        None,
    )
    failed = CellRecord(
        replace(other.cell, seed=0, key="k-f"),
        "failed",
        tmp_path,
        None,
        None,
        Failure("boom", "exception", 1, 9.0, None),
    )
    paired = compare_by_log([odometry, failed, other], lambda rec: True)["aces"]
    assert sorted(paired.labels) == ["kiss-icp", "odometry"] and paired.left_out == {}


def test_the_paired_matrix_names_the_seeds_it_compares_when_a_method_ran_several(tmp_path: Path) -> None:
    """Each method's row may show a different seed (a failed seed 0): the matrix said nothing of it."""
    from albot1.report.standard_paired import compare_by_log, paired_lines

    def kiss(rec: CellRecord) -> CellRecord:
        return replace(rec, cell=replace(rec.cell, method="kiss-icp", method_label="kiss-icp"))

    odometry = _record(tmp_path / "o", "aces")
    kiss_done = kiss(_replace_seed(_record(tmp_path / "k", "aces"), 1))
    kiss_failed = replace(kiss_done, cell=replace(kiss_done.cell, seed=0, key="k-f"), status="failed")
    kiss_failed = replace(kiss_failed, failure=Failure("boom", "exception", 1, 9.0, None), metrics=None, result=None)
    paired = compare_by_log([kiss_failed, kiss_done, odometry], lambda rec: True)["aces"]
    assert paired.seeds == {"kiss-icp": 1, "odometry": 0}
    assert (
        "- runs compared: kiss-icp seed 1, odometry seed 0: not the same seed for every method (a failed seed is "
        "replaced by the method's lowest completed one), so a ratio also compares the methods' randomness"
    ) in paired_lines(paired)
    same = compare_by_log([odometry, _replace_seed(odometry, 1), kiss(odometry)], lambda rec: True)["aces"]
    assert "- runs compared: odometry seed 0, kiss-icp seed 0" in paired_lines(same)
    one_seed = compare_by_log([odometry, kiss(odometry)], lambda rec: True)["aces"]
    assert one_seed.seeds == {} and not any(line.startswith("- runs compared") for line in paired_lines(one_seed))


def test_published_figures_read_as_their_sources_print_them_not_padded_to_the_page_decimals(tmp_path: Path) -> None:
    """Hess et al. print GM on ACES as 0.044 ± 0.044 m and 0.4 ± 0.4 deg: 0.0440 ± 0.0440 and 0.400 ± 0.400 deg
    claimed a precision the source does not give. Measured rows keep the page's decimals."""
    rec = _record(tmp_path / "runs", "aces")
    out = tmp_path / "report"
    out.mkdir()
    page, _ = write_standard(_plan([]), [rec], out)
    lines = page.read_text().splitlines()
    gm = "| GM (Kuemmerle et al. 2009) | **published** | 0.044 ± 0.044 | n/a | n/a | n/a | 0.4 ± 0.4 | n/a | n/a |"
    assert any(line.startswith(gm) for line in lines)
    assert any(
        line.startswith("| SM (Kuemmerle et al. 2009) | **published** | 0.220 ± 0.296 | n/a |") for line in lines
    )
    summary = next(line for line in lines if line.startswith("| GM (Kuemmerle et al. 2009) (**published**) |"))
    assert summary == "| GM (Kuemmerle et al. 2009) (**published**) | 0.044 | 0.031 | 0.004 | 0.056 | 0.143 |"
    assert any(line.startswith("| odometry | measured | 0.3167 ± 0.4193 |") for line in lines)
