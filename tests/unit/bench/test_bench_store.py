"""Results store and the verdict on a finished cell process (no processes started here)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from albot1.bench.cell_main import ERROR_FILE, EXIT_EXCEPTION, EXIT_MEMORY, EXIT_STORAGE
from albot1.bench.errors import BenchError
from albot1.bench.grid import Cell, GridPlan, Skipped
from albot1.bench.job import judge
from albot1.bench.limits import ChildExit
from albot1.bench.store import ResultsStore
from conftest import write_complete_run


def make_cell(**changes: object) -> Cell:
    values: dict[str, object] = dict(
        suite="t",
        dataset="w",
        dataset_label="w[:10]",
        method="odometry",
        method_label="odometry",
        preset="default",
        degradation="none",
        seed=0,
        key="k1",
        code_version="v",
        time_s=7,
        memory_mb=123,
        limit=10,
    )
    values.update(changes)
    return Cell(**values)  # type: ignore[arg-type]


def test_cell_and_plan_round_trip_through_json() -> None:
    cell = make_cell(overrides={"a": 1}, config={"a": 1})
    assert Cell.from_json(json.loads(json.dumps(cell.to_json()))) == cell
    # a grid.json written before suites named registered methods only: empty plugin fields are read, a target is not
    legacy = {**cell.to_json(), "target": None, "error_class": None, "requires": []}
    assert Cell.from_json(legacy) == cell
    with pytest.raises(TypeError, match="names a suite-defined target, which is no longer read"):
        Cell.from_json({**cell.to_json(), "target": "x:Y"})
    plan = GridPlan(
        "t",
        None,
        "",
        [cell],
        [Skipped("intel", "absent", "albot1 datasets fetch intel")],
        [],
        {},
        [0],
        ["none"],
        {"cpu_count": 2},
    )
    again = GridPlan.from_json(json.loads(json.dumps(plan.to_json())))
    assert again.cells == [cell] and again.skipped_datasets == plan.skipped_datasets


def test_complete_needs_done_and_parseable_metrics(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path)
    run_dir = store.prepare(make_cell())
    assert not store.is_complete("k1")
    (run_dir / "DONE").write_text("k1\n")
    assert not store.is_complete("k1")  # evaluation missing: the cell is re-evaluated, not kept
    (run_dir / "metrics.json").write_text('{"ate": ')
    assert not store.is_complete("k1")  # a torn file never counts
    (run_dir / "metrics.json").write_text('{"ate": null}')
    assert not store.is_complete("k1")  # no result.json: nothing the report could read
    write_complete_run(run_dir, "k1")
    (run_dir / "metrics.json").write_text('{"ate": null}')
    assert store.is_complete("k1")


def test_failure_is_recorded_and_cleared_by_the_next_attempt(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path)
    cell = make_cell()
    store.record_failure(cell, "boom", "exception", exit_code=2, elapsed_s=1.5, traceback_text="Traceback ...")
    failure = store.failure("k1")
    assert failure is not None and (failure.reason, failure.kind, failure.exit_code) == ("boom", "exception", 2)
    assert "Traceback" in (store.run_dir("k1") / "cell.log").read_text()
    store.prepare(cell)
    assert store.failure("k1") is None


def test_lock_refuses_a_second_runner(tmp_path: Path) -> None:
    first, second = ResultsStore(tmp_path), ResultsStore(tmp_path)
    first.lock()
    try:
        with pytest.raises(BenchError, match="another `albot1 bench` is running"):
            second.lock()
    finally:
        first.unlock()
    second.lock()
    second.unlock()


def test_read_plan_of_a_folder_that_is_not_a_results_folder(tmp_path: Path) -> None:
    with pytest.raises(BenchError, match="no grid.json"):
        ResultsStore(tmp_path).read_plan()


def test_read_plan_says_what_the_path_is_when_it_is_no_folder(tmp_path: Path) -> None:
    """A typo or a file is named as such, not as a folder missing its grid.json."""
    (tmp_path / "afile").write_text("x")
    for name, found in [
        ("nonexist", "does not exist; expected a results folder of `albot1 bench`"),
        ("afile", "is a file, not a results folder of `albot1 bench`"),
    ]:
        with pytest.raises(BenchError) as info:
            ResultsStore(tmp_path / name).read_plan()
        assert str(info.value) == f"{tmp_path / name}: {found}; run `albot1 bench SUITE` first"


@pytest.mark.parametrize(
    ("ended", "error", "kind", "words"),
    [
        (ChildExit(None, True, 7.1), None, "timeout", "time limit exceeded: no result after 7 s"),
        (
            ChildExit(None, False, 2.0, memory_exceeded=True, peak_rss_mb=140.4),
            None,
            "memory",
            "memory limit exceeded: resident memory reached 140.4 MB, over the cell's limit of 123 MB (killed)",
        ),
        (ChildExit(-11, False, 1.0), None, "crash", "killed by SIGSEGV (a native library crashed)"),
        (ChildExit(-9, False, 1.0), None, "crash", "out-of-memory killer"),
        (ChildExit(-9, False, 1.0, abandoned=True), None, "interrupted", "the runner gave the cell up while it ran"),
        (ChildExit(-15, False, 1.0), None, "crash", "killed by SIGTERM (stopped from outside: the cell pool"),
        (
            ChildExit(255, False, 1.0, pool_lost="was killed by SIGKILL"),
            None,
            "executor",
            "the cell process pool was shut down: its forkserver was killed by SIGKILL while the cell ran",
        ),
        (
            ChildExit(EXIT_MEMORY, False, 1.0),
            {"kind": "memory", "type": "MemoryError", "message": ""},
            "memory",
            "out of memory (an allocation was refused): MemoryError",
        ),
        (
            ChildExit(EXIT_STORAGE, False, 1.0),
            {"kind": "storage", "type": "OSError", "message": "[Errno 28] No space left on device", "errno": 28},
            "storage",
            "cannot write the results: no space left on device",
        ),
        (ChildExit(EXIT_STORAGE, False, 1.0), None, "storage", "cannot write the results in "),
        (
            ChildExit(EXIT_EXCEPTION, False, 1.0),
            {"kind": "exception", "type": "BaselineError", "message": "diverged"},
            "exception",
            "BaselineError: diverged",
        ),
        (ChildExit(1, False, 1.0), None, "crash", "exited with code 1 without an error report"),
        (
            ChildExit(0, False, 1.0),
            None,
            "exception",
            "the cell process exited with code 0 but left no complete run (DONE and metrics.json) and no error "
            "report: something in it ended the process early (a method calling os._exit(0)?)",
        ),
    ],
)
def test_judge_names_every_way_a_cell_can_end(
    tmp_path: Path, ended: ChildExit, error: dict | None, kind: str, words: str
) -> None:
    store = ResultsStore(tmp_path)
    run_dir = store.prepare(make_cell())
    if error is not None:
        (run_dir / ERROR_FILE).write_text(json.dumps(error))
    verdict = judge(make_cell(), store, ended)
    assert verdict is not None
    assert verdict[0] == kind and words in verdict[1]
    assert not (run_dir / ERROR_FILE).exists()


def test_judge_accepts_a_complete_cell(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path)
    run_dir = store.prepare(make_cell())
    write_complete_run(run_dir, "k1")
    assert judge(make_cell(), store, ChildExit(0, False, 1.0)) is None


@pytest.mark.parametrize(
    "ended",
    [
        ChildExit(None, True, 1.04),
        ChildExit(None, False, 1.0, memory_exceeded=True, peak_rss_mb=140.4),
        ChildExit(-9, False, 1.0),
        ChildExit(255, False, 1.0, pool_lost="was killed by SIGKILL"),
    ],
)
def test_judge_accepts_a_cell_killed_after_its_result_was_complete(tmp_path: Path, ended: ChildExit) -> None:
    """A kill that lands while the child exits, after DONE and metrics.json, leaves a complete cell.

    `albot1 bench` used to record it as a timeout (FAILED.json beside the complete result: the bench printed
    FAILED, "no result after 1 s", while `albot1 report` counted the cell complete).
    """
    store = ResultsStore(tmp_path)
    run_dir = store.prepare(make_cell())
    write_complete_run(run_dir, "k1")
    assert judge(make_cell(), store, ended) is None


def test_judge_keeps_a_timeout_when_the_result_is_half_written(tmp_path: Path) -> None:
    """DONE without metrics.json is no result: the timeout stands."""
    store = ResultsStore(tmp_path)
    run_dir = store.prepare(make_cell())
    (run_dir / "DONE").write_text("k1\n")
    assert judge(make_cell(), store, ChildExit(None, True, 1.04)) == (
        "timeout",
        "time limit exceeded: no result after 7 s (killed)",
    )


def test_a_done_folder_holding_no_run_of_its_cell_is_named_and_run_again(tmp_path: Path) -> None:
    """A truncated result.json or another cell's files under DONE: neither kept as a result nor dropped in silence.

    The bench used to keep such a folder as complete (it read only DONE and metrics.json): the report then
    failed on its result.json at every build, or showed another cell's numbers under this cell's name.
    """
    store = ResultsStore(tmp_path)
    run_dir = store.prepare(make_cell())
    write_complete_run(run_dir, "k1")
    (run_dir / "result.json").write_text((run_dir / "result.json").read_text()[:40])
    assert not store.is_complete("k1")
    assert (store.damage("k1") or "").startswith(f"{run_dir / 'result.json'}: cannot read a ResultRecord: ")
    write_complete_run(run_dir, "0123456789abcdef")  # a folder copied from another cell's
    assert not store.is_complete("k1")
    assert store.damage("k1") == (
        f"{run_dir / 'result.json'}: holds the run of cell '0123456789abcdef', not of k1, the folder's name "
        "(a run folder copied or renamed?)"
    )
    store.prepare(make_cell())  # its next attempt runs the method again instead of only evaluating those files
    assert not (run_dir / "DONE").exists() and store.damage("k1") is None


def test_a_done_folder_with_a_torn_metrics_json_is_named_and_only_evaluated_again(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path)
    run_dir = store.prepare(make_cell())
    write_complete_run(run_dir, "k1")
    (run_dir / "metrics.json").write_text('{"ate": ')
    assert (store.damage("k1") or "").startswith(f"{run_dir / 'metrics.json'}: not a metrics record written by")
    store.prepare(make_cell())
    assert (run_dir / "DONE").exists()  # the run itself is sound: its next attempt evaluates it
    (run_dir / "metrics.json").unlink()
    assert store.damage("k1") is None and not store.is_complete("k1")  # stopped before its evaluation: no damage
