"""Longest-expected-first order of a grid's cells, from the wall times of earlier attempts in the stores."""

from __future__ import annotations

import concurrent.futures as cf
import json
import os
from pathlib import Path

from albot1.bench.grid import Cell, CellOutcome, GridPlan
from albot1.bench.order import longest_first, past_costs, signature
from albot1.bench.runner import run_grid
from albot1.bench.store import ResultsStore


def cell(method: str, dataset: str, key: str, *, seed: int = 0, code: str = "new") -> Cell:
    return Cell(
        suite="t",
        dataset=dataset,
        dataset_label=dataset,
        method=method,
        method_label=method,
        preset="default",
        degradation="none",
        seed=seed,
        key=key,
        code_version=code,
        time_s=60,
        memory_mb=100,
    )


def stored(store: Path, old: Cell, *, elapsed: float | None, failed: bool = False, mtime: float | None = None) -> None:
    """A run folder of an earlier attempt of ``old`` that took ``elapsed`` seconds."""
    run_dir = store / "runs" / old.key
    run_dir.mkdir(parents=True)
    (run_dir / "cell.json").write_text(json.dumps(old.to_json()))
    if elapsed is not None:
        name = "FAILED.json" if failed else "attempt.json"
        (run_dir / name).write_text(json.dumps({"elapsed_s": elapsed, "host": "h", "finished": "t"}))
    if mtime is not None:
        os.utime(run_dir / "cell.json", (mtime, mtime))


def test_cells_start_longest_first_matched_across_code_versions(tmp_path: Path) -> None:
    store = tmp_path / "results" / "default"
    stored(store, cell("odometry", "a", "o1", code="old"), elapsed=1.0)
    stored(store, cell("gtsam", "a", "o2", code="old"), elapsed=9.0)
    stored(store, cell("gtsam", "b", "o3", code="old"), elapsed=30.0, failed=True)  # a failure's time counts too
    stored(store, cell("odometry", "b", "o4", code="old"), elapsed=None)  # no time recorded: passed over
    (store / "runs" / "junk").mkdir()  # no cell.json: passed over
    plan = [cell("odometry", "a", "n1"), cell("gtsam", "a", "n2")]
    plan += [cell("odometry", "b", "n3"), cell("gtsam", "b", "n4")]
    known = past_costs([store])
    assert len(known) == 3
    ordered = longest_first(plan, known)
    # odometry on b: never timed, so it costs its method's median (1.0) and keeps its plan place after odometry on a
    assert [c.key for c in ordered] == ["n4", "n2", "n1", "n3"]


def test_unknown_method_costs_the_median_of_all_known_cells(tmp_path: Path) -> None:
    store = tmp_path / "s"
    for index, elapsed in enumerate([1.0, 2.0, 10.0]):
        stored(store, cell("odometry", f"d{index}", f"o{index}", code="old"), elapsed=elapsed)
    plan = [cell("odometry", "d0", "n0"), cell("new-method", "d0", "n1"), cell("odometry", "d2", "n2")]
    assert [c.key for c in longest_first(plan, past_costs([store]))] == ["n2", "n1", "n0"]


def test_nothing_known_keeps_the_plan_order(tmp_path: Path) -> None:
    plan = [cell("odometry", "a", "n1"), cell("gtsam", "a", "n2")]
    assert longest_first(plan, past_costs([tmp_path / "absent"])) == plan
    assert longest_first([], {}) == []


def test_the_newest_attempt_of_a_signature_wins(tmp_path: Path) -> None:
    store = tmp_path / "s"
    stored(store, cell("gtsam", "a", "old1", code="v1"), elapsed=50.0, mtime=1_000.0)
    stored(store, cell("gtsam", "a", "old2", code="v2"), elapsed=5.0, mtime=2_000.0)
    assert set(past_costs([store]).values()) == {5.0}


def test_signature_tells_apart_what_a_cell_runs_but_not_its_code() -> None:
    base = cell("gtsam", "a", "k")
    assert signature(base.to_json()) == signature(cell("gtsam", "a", "other", code="v9").to_json())
    assert signature(base.to_json()) != signature(cell("gtsam", "a", "k", seed=1).to_json())
    assert signature({"method_label": "x"}) is None


def test_run_grid_submits_the_longest_expected_cell_first(tmp_path: Path) -> None:
    root = tmp_path / "results" / "t"
    stored(root, cell("gtsam", "a", "old", code="old"), elapsed=40.0)  # this store's runs of an older code
    stored(root, cell("odometry", "a", "old2", code="old"), elapsed=0.5)
    stored(tmp_path / "results" / "other", cell("odometry", "a", "o3", code="old"), elapsed=99.0)  # not read
    cells = [cell("odometry", "a", "n1"), cell("gtsam", "a", "n2")]
    plan = GridPlan("t", None, "", cells, [], [], {}, [0], ["none"], {})
    store = ResultsStore(root)
    store.write_plan(plan)
    ran: list[str] = []

    def job(c: Cell, _root: str) -> CellOutcome:
        ran.append(c.key)
        return CellOutcome.of(c, "done", 0.0)

    with cf.ThreadPoolExecutor(max_workers=1) as pool:  # one worker: cells run in the order submitted
        summary = run_grid(plan, store, pool, job=job)
    assert ran == ["n2", "n1"]
    assert sorted(o.key for o in summary.outcomes) == ["n1", "n2"]
