"""Held-in marks on the paired comparisons (``metrics.md``, ``paired.csv``) and the interactive views.

"A beats B on D" where A or B was tuned on D says how well one fits D, not which generalises; the paired
blocks named both sides without the mark, and ``paired.csv`` had no held-in column for either side. The
interactive view of ``index.html`` named a held-in run's trajectory and map without the mark.
"""

from __future__ import annotations

import csv
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from albot1.bench.grid import Cell
from albot1.data.model import Frame, Scan, Sequence
from albot1.metrics.record import MetricsRecord
from albot1.records import ResultRecord, read_record
from albot1.report import results_data, tuning
from albot1.report.collect import CellRecord
from albot1.report.interactive import dataset_figure
from albot1.report.interactive_page import write_views
from albot1.report.paired_tables import html_table, markdown_lines, paired_rows
from albot1.report.results_data import AteCell, ResultsData, VerdictRow
from albot1.report.results_page import _verdict_lines, ate_table, tally_text
from albot1.report.tables import write_tables
from albot1.report.thesis.evidence import Evidence, Store
from albot1.report.thesis.experiments.common import ATE, cell, number
from albot1.report.thesis.page import _tally, _verdict_cell
from albot1.report.thesis.verdicts import all_of, at_most, lower_than
from albot1.report.tuning import LEGEND, MARK
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

#: a synthetic world gtsam-graph's [tuned_on] lists and kiss-icp's does not (odometry: none)
WORLD = "synthetic-office-loop"
SCANS = 40


def _record(root: Path, method: str, error: float, seed: int) -> CellRecord:
    """An odometry run of a straight drive (odometry ``error`` off) filed as ``method``'s cell on :data:`WORLD`."""
    t = np.arange(SCANS, dtype=float)
    truth = np.column_stack([t * 0.5, np.zeros(SCANS), np.zeros(SCANS)])
    odometry = np.column_stack([t * 0.5 * (1 + error), np.zeros(SCANS), np.radians(error) * t])
    angles = np.radians(np.linspace(-90.0, 90.0, 181))
    frames = [
        Frame(i, Scan(np.full(181, 5.0), angles, 100.0 + t[i], 30.0), odometry[i], reference=truth[i])
        for i in range(SCANS)
    ]
    sequence = Sequence.from_frames("drive", frames)
    run_dir = write_run(run_method("odometry", sequence, dataset_name="drive"), root / f"{method}-{seed}")
    evaluate_run(run_dir)
    cell = Cell("t", WORLD, WORLD, method, method, "default", "none", seed, f"{method}-{seed}", "v", 1.0, 1.0)
    metrics = read_record(MetricsRecord, run_dir / "metrics.json")
    return CellRecord(cell, "done", run_dir, read_record(ResultRecord, run_dir / "result.json"), metrics, None)


@pytest.fixture(scope="module")
def records(tmp_path_factory: pytest.TempPathFactory) -> list[CellRecord]:
    root = tmp_path_factory.mktemp("heldin-paired")
    out = []
    for seed in (0, 1):
        out += [
            _record(root, "odometry", 0.10, seed),
            _record(root, "gtsam-graph", 0.02, seed),  # the best, and held-in on WORLD
            _record(root, "kiss-icp", 0.10, seed),  # held-out on WORLD
            _record(root, "my-plugin", 0.10, seed),  # no [tuned_on] anywhere: unknown
        ]
    return out


def test_each_side_of_a_paired_comparison_says_whether_it_is_held_in(records: list[CellRecord]) -> None:
    rows = {r.method: r for r in paired_rows(records)}
    assert rows["kiss-icp"].best == "gtsam-graph"
    assert rows["kiss-icp"].held_in == {"odometry": False, "gtsam-graph": True, "kiss-icp": False, "my-plugin": None}
    lines = markdown_lines(list(rows.values()), WORLD)
    by_method = {line.split("|")[1].strip(): line for line in lines if line.startswith("| ") and "---" not in line}
    assert f"gtsam-graph {MARK}" in by_method  # the held-in method's own row
    assert "kiss-icp" in by_method and "odometry" in by_method and "my-plugin" in by_method
    # the claim "kiss-icp is worse than the best" names the held-in best with its mark
    assert f"(gtsam-graph {MARK})" in by_method["kiss-icp"] and f"(odometry {MARK})" not in by_method["kiss-icp"]
    assert f"- {LEGEND}" in lines
    html = html_table(list(rows.values()), WORLD)
    assert f"gtsam-graph {MARK}</td>" in html and f"(gtsam-graph {MARK})" in html and "measured on a dataset" in html


def test_paired_csv_has_a_held_in_column_per_side(records: list[CellRecord], tmp_path: Path) -> None:
    write_tables(records, tmp_path)
    with (tmp_path / "paired.csv").open(encoding="utf-8") as handle:
        lines = list(csv.DictReader(handle))
    side = {(r["method"], r["role"]): (r["held_in"], r["against_held_in"]) for r in lines}
    assert side[("kiss-icp", "best")] == ("False", "True")  # kiss-icp against the held-in best
    assert side[("gtsam-graph", "reference")] == ("True", "False")  # the held-in method against odometry
    assert side[("my-plugin", "reference")] == ("", "False")  # unknown tuning is empty, never False
    assert side[("odometry", "best")] == ("False", "True")
    metrics = (tmp_path / "metrics.md").read_text(encoding="utf-8")
    paired_part = metrics[metrics.index("Paired comparison") :]
    assert f"(gtsam-graph {MARK})" in paired_part


def test_the_interactive_view_names_a_held_in_run_with_the_mark(records: list[CellRecord]) -> None:
    figure = dataset_figure(records, WORLD, {})
    assert figure is not None
    names = {trace["name"] for trace in figure["data"] if "legendgroup" in trace and "map" not in trace["name"]}
    assert f"gtsam-graph {MARK} [none, seed 0]" in names
    assert "kiss-icp [none, seed 0]" in names and "my-plugin [none, seed 0]" in names
    hover = next(t["hovertemplate"] for t in figure["data"] if "hovertemplate" in t and "gtsam" in t["name"])
    assert f"<b>gtsam-graph {MARK}</b>" in hover
    assert LEGEND in figure["notes"]


def test_a_changed_tuned_on_list_draws_the_view_again(
    records: list[CellRecord], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The marks come from the preset files, which no run's digest covers: a cached view kept its old labels."""
    with monkeypatch.context() as patch:
        patch.setattr(tuning, "tuned_on", lambda owner, preset: ())
        tuning.tuned_datasets.cache_clear()
        _, views = write_views(records, tmp_path, {})
        assert not _marked_in_script(views[WORLD].script.read_text(encoding="utf-8"))
    tuning.tuned_datasets.cache_clear()
    _, views = write_views(records, tmp_path, {})
    assert _marked_in_script(views[WORLD].script.read_text(encoding="utf-8"))
    assert LEGEND in views[WORLD].notes


def _marked_in_script(text: str) -> bool:
    """Whether a view's script names gtsam-graph with the mark (plotly's JSON may escape it as ``\\u2020``)."""
    return any(f"gtsam-graph {mark}" in text for mark in (MARK, MARK.encode("ascii", "backslashreplace").decode()))


# --------------------------------------------------------------------------- the thesis page


def _thesis_evidence(records: list[CellRecord]) -> Evidence:
    """The paired fixture's runs filed as the thesis preset (held-in on WORLD) and odometry, in one store."""
    thesis = [
        replace(r, cell=replace(r.cell, method="albot1", method_label="albot1:thesis", preset="thesis"))
        for r in records
        if r.cell.method == "gtsam-graph"
    ]
    odometry = [r for r in records if r.cell.method == "odometry"]
    return Evidence(
        [Store("thesis", Path("results/thesis"), cast(Any, SimpleNamespace(machine={})), thesis + odometry)]
    )


def test_a_thesis_verdict_and_number_on_a_tuned_dataset_carry_the_mark(records: list[CellRecord]) -> None:
    from albot1.report.thesis.experiments.common import tagged  # new here: the module's other tests run without it

    ev = _thesis_evidence(records)
    mine = number(ev, WORLD, "albot1:thesis", ATE, "albot1:thesis ATE", "m")
    odometry = number(ev, WORLD, "odometry", ATE, "odometry ATE", "m")
    assert mine.known and mine.held_in is True and odometry.held_in is False
    assert tagged(cell(mine), mine).endswith(f" {MARK}") and MARK not in tagged(cell(odometry), odometry)
    assert tagged(f"{cell(mine)} / {cell(mine)}", mine, mine).count(MARK) == 1  # once per table cell
    assert lower_than(mine, odometry).held_in and at_most(mine, 10.0).held_in and not at_most(odometry, 10.0).held_in
    assert all_of([at_most(odometry, 10.0), at_most(mine, 10.0)]).held_in
    assert _verdict_cell(at_most(mine, 10.0)).startswith(f"**holds** {MARK}: ")
    assert _verdict_cell(at_most(odometry, 10.0)).startswith("**holds**: ")
    mixed = [at_most(mine, 10.0), at_most(odometry, 10.0), at_most(mine, 10.0)]
    assert _tally(mixed) == f"holds 3 (of 3 datasets, 2 held-in {MARK})"
    assert _tally([at_most(odometry, 10.0)] * 2) == "holds 2 (of 2 datasets)"


def test_the_results_page_counts_held_in_thesis_verdicts() -> None:
    assert (
        tally_text({"holds": 2, "does not hold": 1}, 3)
        == f"holds 2, does not hold 1 (of 3 datasets, all held-in {MARK})"
    )
    assert tally_text({"holds": 1}, 1) == f"**holds** {MARK}"
    assert tally_text({"holds": 2}) == "holds 2 (of 2 datasets)"
    row = VerdictRow("Experiment 1", "shape kept", "3.2.1", {"thesis preset": {"holds": 2}}, {"thesis preset": 1})
    data = ResultsData("c", [], {}, "m", [], verdict_columns={"thesis preset": "thesis preset"}, verdicts=[row])
    assert f"holds 2 (of 2 datasets, 1 held-in {MARK})" in "\n".join(_verdict_lines(data))
    assert ResultsData.from_json(data.to_json(), "x").verdicts[0].held_in == {"thesis preset": 1}


def test_an_external_cell_is_unknown_whatever_its_label(records: list[CellRecord]) -> None:
    """A suite's external cell (another system's trajectory file) labelled like a registered method read that
    method's tuning; the file's maker records none here."""
    cell = next(r.cell for r in records if r.cell.method == "gtsam-graph")
    assert tuning.held_in(cell) is True
    assert tuning.held_in(replace(cell, trajectory="their.tum")) is None


def test_the_results_pages_key_ate_cells_carry_the_mark() -> None:
    """docs/results.md's "ATE on the key degraded cells" showed gtsam-graph on intel-corrected (held-in) bare."""
    where = ("intel-corrected?odometry=laser-pose", "gauss:0.1:1")
    cells = [AteCell(*where, "gtsam-graph", seed, 0.07, "", True) for seed in (0, 1)]
    cells += [AteCell(*where, "odometry", seed, 3.5, "", False) for seed in (0, 1)]
    cells += [AteCell(*where, "my-plugin", 0, 0.1, "", None)]
    data = ResultsData("c", [], {}, "m", [], ate=cells)
    row = next(line for line in ate_table(data) if line.startswith("| `intel-corrected"))
    assert f"| 0.0700 / 0.0700 {MARK} | 3.5000 / 3.5000 | 0.1000 / – |" in row


def test_the_key_ate_cells_are_read_with_their_marks(
    records: list[CellRecord], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(results_data, "KEY_ATE", ((WORLD, "none"),))
    marks = {(c.method, c.seed): c.held_in for c in results_data.ate_cells(records)}
    assert marks[("gtsam-graph", 0)] is True and marks[("odometry", 1)] is False and marks[("my-plugin", 0)] is None
