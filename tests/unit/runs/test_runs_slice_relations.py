"""Which ground-truth relations a run on a slice of a log is scored on: one rule for `albot1 run` and the bench.

A small CARMEN log (20 scans on a straight line, 0.5 s apart) with a relations file of 8 pairs, each off
by a known 0.1 m step in x (relation k is off by 0.1 * (k + 1) m), so every number below is exact:

* ``[:10]`` (scans 0-9) can score 4 relations (0.1 .. 0.4 m, mean 0.25 m) and leaves out 4;
* ``[:10:2]`` (scans 0, 2, 4, 6, 8) can score 2 (0.2 and 0.4 m, mean 0.3 m) and leaves out 6 (the old
  time-span rule of `albot1 evaluate` failed here: scan 1 lies inside the run's time span but was skipped);
* the whole log scores all 8 and leaves out none.

`albot1 run` + `albot1 evaluate` and a bench cell (real planner, real cell executor) must store the
dataset's relations, score the same relations and report the same counts in ``metrics.json``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from albot1.bench.cells import execute_cell
from albot1.bench.plan import plan_suite
from albot1.bench.store import ResultsStore
from albot1.bench.suite import parse_suite
from albot1.cli.app import app
from albot1.data.model import Relations
from albot1.data.relations import read_relations, write_relations
from albot1.metrics.measures.relations import RelationsBlock
from albot1.metrics.record import MetricsRecord
from albot1.runs.folder import METRICS_FILE
from albot1.settings import get_settings

SCANS = 20
#: (scan of t1, scan of t2) of each relation; (12, 8) has t2 < t1 as some published lines do.
PAIRS = [(0, 1), (2, 4), (6, 9), (2, 8), (3, 12), (10, 15), (0, 19), (12, 8)]


def _stamp(scan: int) -> float:
    return 100.0 + 0.5 * scan


def _write_log(folder: Path) -> tuple[Path, Path]:
    """A 180-beam FLASER log moving 0.1 m per scan along x, and its relations file."""
    ranges = " ".join(["2.0"] * 180)
    lines = []
    for scan in range(SCANS):
        x, t = 0.1 * scan, _stamp(scan)
        lines.append(f"FLASER 180 {ranges} {x:.6f} 0.0 0.0 {x:.6f} 0.0 0.0 {t:.6f} host {t:.6f}")
    log = folder / "line.clf"
    log.write_text("\n".join(lines) + "\n")
    i = np.array([p[0] for p in PAIRS])
    j = np.array([p[1] for p in PAIRS])
    offset = 0.1 * (np.arange(len(PAIRS)) + 1)  # relation k is off by 0.1 * (k + 1) m along x
    poses = np.column_stack([0.1 * (j - i) + offset, np.zeros(len(PAIRS)), np.zeros(len(PAIRS))])
    rel = folder / "line.relations"
    write_relations(rel, Relations(_stamps(i), _stamps(j), poses))
    return log, rel


def _stamps(scans: np.ndarray) -> np.ndarray:
    return np.array([_stamp(int(s)) for s in scans])


@pytest.fixture
def dataset(tmp_path: Path) -> str:
    """The log as a dataset reference: its path with the relations file as a loader option."""
    log, rel = _write_log(tmp_path)
    return f"{log}?relations={rel}"


def _cli_metrics(ref: str, out: Path) -> tuple[dict[str, Any], str]:
    """`albot1 run odometry REF --out OUT` then `albot1 evaluate RUN`: the relations block and the printed line."""
    runner = CliRunner()
    ran = runner.invoke(app, ["run", "odometry", ref, "--out", str(out), "--json"], catch_exceptions=False)
    assert ran.exit_code == 0, ran.output
    run_dir = Path(json.loads(ran.stdout)["run_dir"])
    evaluated = runner.invoke(app, ["evaluate", str(run_dir)], catch_exceptions=False)
    assert evaluated.exit_code == 0, evaluated.output
    assert len(read_relations(run_dir / "relations.txt")) == len(PAIRS)  # the folder keeps the dataset's relations
    line = next(row for row in evaluated.stdout.splitlines() if row.strip().startswith("relations "))
    return json.loads((run_dir / METRICS_FILE).read_text())["relations"], line


def _bench_metrics(ref: str, limit: int | None, stride: int | None, results: Path) -> RelationsBlock:
    """The same slice as one cell of a suite, through the real planner and cell executor."""
    entry: dict[str, object] = {"name": ref}
    if limit is not None:
        entry["limit"] = limit
    if stride is not None:
        entry["stride"] = stride
    data = {"grid": {"degradations": ["none"], "seeds": [0]}, "methods": [{"name": "odometry"}], "datasets": [entry]}
    plan = plan_suite(parse_suite(data, name="slices", source="slices.toml"), get_settings())
    assert len(plan.cells) == 1
    store = ResultsStore(results)
    run_dir = execute_cell(plan.cells[0], store.runs)
    assert len(read_relations(run_dir / "relations.txt")) == len(PAIRS)
    record = MetricsRecord.model_validate_json((run_dir / METRICS_FILE).read_text())
    assert record.relations is not None, record.reason("relations")
    return record.relations


@pytest.mark.parametrize(
    ("limit", "stride", "used", "errors_m"),
    [
        (10, None, 4, [0.1, 0.2, 0.3, 0.4]),
        (10, 2, 2, [0.2, 0.4]),
        (None, None, 8, [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]),
    ],
)
def test_run_evaluate_and_a_bench_cell_score_the_same_relations_of_a_slice_and_count_the_rest(
    dataset: str, tmp_path: Path, limit: int | None, stride: int | None, used: int, errors_m: list[float]
) -> None:
    body = "" if limit is None and stride is None else f"[:{limit or ''}{f':{stride}' if stride else ''}]"
    block, line = _cli_metrics(dataset + body, tmp_path / "runs")
    dropped = len(PAIRS) - used
    assert (block["relations_total"], block["relations_used"], block["relations_outside_run"]) == (
        len(PAIRS),
        used,
        dropped,
    )
    assert block["translation_m"]["n"] == used
    assert block["translation_m"]["mean"] == pytest.approx(np.mean(errors_m), abs=1e-9)
    assert block["translation_m"]["max"] == pytest.approx(max(errors_m), abs=1e-9)
    if dropped:
        assert line.endswith(
            f"N = {used} ({dropped} of {len(PAIRS)} relations left out: "
            "they name scans without a pose in this trajectory)"
        )
    else:
        assert line.endswith(f"N = {used}")

    # The suite's slice as the entry's limit/stride, and as part of the entry's own name (`NAME[:10]`).
    entries = [(dataset, limit, stride)] + ([(dataset + body, None, None)] if body else [])
    for name, entry_limit, entry_stride in entries:
        cell = _bench_metrics(name, entry_limit, entry_stride, tmp_path / f"results-{entry_limit}")
        assert (cell.relations_total, cell.relations_used, cell.relations_outside_run) == (len(PAIRS), used, dropped)
        assert cell.translation_m.n == used
        assert cell.translation_m.mean == pytest.approx(block["translation_m"]["mean"], abs=1e-12)
        assert cell.rotation_deg.mean == pytest.approx(block["rotation_deg"]["mean"], abs=1e-12)


def test_a_slice_that_sees_no_relation_pair_reports_every_relation_as_left_out(dataset: str, tmp_path: Path) -> None:
    """Scans 0 and 1 are the ends of relation 0 only; [:1] keeps scan 0 alone, so nothing can be scored."""
    block, line = _cli_metrics(dataset + "[:1]", tmp_path / "runs")
    assert (block["relations_total"], block["relations_used"], block["relations_outside_run"]) == (8, 0, 8)
    assert block["translation_m"]["n"] == 0
    assert "N = 0 (8 of 8 relations left out" in line
