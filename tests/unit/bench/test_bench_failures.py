"""Failures that are not a cell's own: a full or read-only results folder, a killed process pool, limits.

ENOSPC is injected by monkeypatching the writers (the integration test
``test_bench_disk_full.py`` fills a real tmpfs); the limit tests start small
real child processes.
"""

from __future__ import annotations

import concurrent.futures as cf
import errno
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import psutil
import pytest

from albot1.bench import cell_main, job
from albot1.bench import store as store_module
from albot1.bench.errors import BenchError
from albot1.bench.grid import Cell, CellOutcome, GridPlan
from albot1.bench.limits import ChildExit, _server_fate, supervise, watch
from albot1.bench.runner import bench_results_root, run_grid
from albot1.bench.store import ATTEMPT, FAILED, ResultsStore
from conftest import write_complete_run

ENOSPC = OSError(errno.ENOSPC, "No space left on device")


def make_cell(key: str = "k1", **changes: object) -> Cell:
    values: dict[str, object] = dict(
        suite="t",
        dataset="w",
        dataset_label="w",
        method="odometry",
        method_label="odometry",
        preset="default",
        degradation="none",
        seed=0,
        key=key,
        code_version="v",
        time_s=5,
        memory_mb=100,
    )
    values.update(changes)
    return Cell(**values)  # type: ignore[arg-type]


def plan_of(cells: list[Cell], config_failures: dict[str, str] | None = None) -> GridPlan:
    return GridPlan("t", None, "", cells, [], [], config_failures or {}, [0], ["none"], {})


# -- the store ----------------------------------------------------------------------------------------------------


def test_record_failure_never_raises_for_a_full_disk(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    store = ResultsStore(tmp_path)
    store.prepare(make_cell())

    def full(path: Path, data: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(store_module, "write_json", full)
    problem = store.record_failure(make_cell(), "boom", "exception")
    assert problem == f"{tmp_path / 'runs' / 'k1' / FAILED}: cannot be written: No space left on device"


def test_a_storage_failure_frees_the_attempts_files_but_never_a_complete_cell(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path)
    failed_dir = store.prepare(make_cell("bad"))
    for name in ("trajectory.tum", "map.npz", ".trajectory.tum.x.tmp.tum", "DONE"):
        (failed_dir / name).write_text("partial")  # DONE without metrics.json: the cell is not complete
    assert store.record_failure(make_cell("bad"), "no space", "storage") is None
    assert sorted(p.name for p in failed_dir.iterdir()) == ["FAILED.json", "cell.json", "cell.log"]

    done_dir = store.prepare(make_cell("good"))
    write_complete_run(done_dir, "good")
    (done_dir / "trajectory.tum").write_text("{}")
    assert store.record_failure(make_cell("good"), "no space", "storage") is None
    assert {"DONE", "metrics.json", "result.json", "trajectory.tum"} <= {p.name for p in done_dir.iterdir()}


def test_prepare_removes_what_a_killed_attempt_left(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path)
    run_dir = store.prepare(make_cell())
    (run_dir / ".result.json.abc.tmp.json").write_bytes(b"")
    (run_dir / cell_main.ERROR_FILE).write_text("{}")
    store.prepare(make_cell())
    assert sorted(p.name for p in run_dir.iterdir()) == ["cell.json", "cell.log"]


# -- the job ------------------------------------------------------------------------------------------------------


def test_a_job_whose_folder_cannot_be_prepared_fails_the_cell_and_halts_the_grid(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def full(self: ResultsStore, cell: Cell) -> Path:
        raise OSError(errno.ENOSPC, "No space left on device", str(self.run_dir(cell.key) / "cell.json"))

    monkeypatch.setattr(ResultsStore, "prepare", full)
    outcome = job.run_cell_job(make_cell(), str(tmp_path))
    assert outcome.status == "failed" and outcome.kind == "storage" and outcome.halts_grid
    assert outcome.reason is not None and outcome.reason.startswith("cannot write the results: no space left on device")


def test_a_job_that_cannot_start_its_process_fails_only_that_cell(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def no_fork(*args: object, **kwargs: object) -> ChildExit:
        raise BlockingIOError(errno.EAGAIN, "Resource temporarily unavailable")

    monkeypatch.setattr(job, "run_limited", no_fork)
    outcome = job.run_cell_job(make_cell(), str(tmp_path))
    assert outcome.kind == "executor" and not outcome.halts_grid
    assert outcome.reason == "cannot start the cell: BlockingIOError: [Errno 11] Resource temporarily unavailable"
    assert json.loads((tmp_path / "runs" / "k1" / FAILED).read_text())["kind"] == "executor"


def test_a_completed_cell_whose_attempt_record_does_not_fit_stays_done_and_halts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def completes(cell: Cell, runs_root: Path, log_path: Path, **_: object) -> ChildExit:
        write_complete_run(runs_root / cell.key, cell.key)
        return ChildExit(0, False, 1.0)

    def full(path: Path, record: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(job, "run_limited", completes)
    monkeypatch.setattr(job, "write_record", full)
    outcome = job.run_cell_job(make_cell(), str(tmp_path))
    assert outcome.status == "done" and outcome.halts_grid and "attempt.json is missing" in (outcome.reason or "")
    assert not (tmp_path / "runs" / "k1" / ATTEMPT).exists()


def test_the_childs_report_names_a_full_disk_even_when_its_error_file_does_not_fit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    wrapped = RuntimeError("kiss-icp on x failed")
    wrapped.__cause__ = OSError(errno.ENOSPC, "No space left on device")
    assert cell_main._report(tmp_path, wrapped) == cell_main.EXIT_STORAGE
    written = json.loads((tmp_path / cell_main.ERROR_FILE).read_text())
    assert written["kind"] == "storage" and written["errno"] == errno.ENOSPC

    assert cell_main._report(tmp_path, RuntimeError("plain")) == cell_main.EXIT_EXCEPTION
    assert cell_main._report(tmp_path, MemoryError()) == cell_main.EXIT_MEMORY

    def full(path: Path, data: object) -> None:
        raise ENOSPC

    monkeypatch.setattr("albot1.runs.folder.write_json", full)
    assert cell_main._report(tmp_path, RuntimeError("plain")) == cell_main.EXIT_STORAGE


# -- the runner ---------------------------------------------------------------------------------------------------


def test_a_halting_failure_starts_no_further_cell_and_lists_the_rest(tmp_path: Path) -> None:
    cells = [make_cell(f"k{i}") for i in range(6)]
    started: list[str] = []

    def fake_job(cell: Cell, root: str) -> CellOutcome:
        started.append(cell.key)
        if cell.key == "k1":
            return CellOutcome.of(
                cell, "failed", 0.0, "cannot write the results: no space left", "storage", halts_grid=True
            )
        return CellOutcome.of(cell, "done")

    store = ResultsStore(tmp_path)
    with cf.ThreadPoolExecutor(max_workers=1) as pool:
        summary = run_grid(plan_of(cells), store, pool, job=fake_job)
    assert started == ["k0", "k1"]
    assert summary.halted == "cannot write the results: no space left"
    assert [c.key for c in summary.not_started] == ["k2", "k3", "k4", "k5"]
    assert summary.counts["done"] == 1 and summary.counts["failed"] == 1


def test_the_thread_that_meets_the_failure_takes_no_next_cell(tmp_path: Path) -> None:
    """Two workers: the one whose cell halts must not start a queued cell before the runner cancels it."""
    cells = [make_cell(f"k{i}") for i in range(8)]
    started: list[str] = []
    lock = threading.Lock()

    def fake_job(cell: Cell, root: str) -> CellOutcome:
        with lock:
            started.append(cell.key)
        if cell.key == "k0":
            return CellOutcome.of(cell, "failed", 0.0, "pool killed", "executor", halts_grid=True)
        time.sleep(0.2)
        return CellOutcome.of(cell, "done")

    with cf.ThreadPoolExecutor(max_workers=2) as pool:
        summary = run_grid(plan_of(cells), ResultsStore(tmp_path), pool, job=fake_job)
    assert "k0" in started and set(started) <= {"k0", "k1"}  # k1 only if the other worker took it first
    assert len(summary.not_started) == 8 - len(started)


def test_a_config_failure_that_cannot_be_recorded_halts_before_any_cell_starts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(ResultsStore, "record_failure", lambda self, *a, **k: "FAILED.json: cannot be written")
    cells = [make_cell("k0"), make_cell("k1")]

    def never(cell: Cell, root: str) -> CellOutcome:
        raise AssertionError("a cell started")

    with cf.ThreadPoolExecutor(max_workers=1) as pool:
        summary = run_grid(plan_of(cells, {"k0": "bad override"}), ResultsStore(tmp_path), pool, job=never)
    assert summary.halted is not None and "bad override" in summary.halted
    assert [c.key for c in summary.not_started] == ["k1"]


def test_an_executor_error_that_cannot_be_recorded_halts(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(ResultsStore, "record_failure", lambda self, *a, **k: "FAILED.json: cannot be written")

    def lost(cell: Cell, root: str) -> CellOutcome:
        raise RuntimeError("worker died")

    with cf.ThreadPoolExecutor(max_workers=1) as pool:
        summary = run_grid(plan_of([make_cell("k0"), make_cell("k1")]), ResultsStore(tmp_path), pool, job=lost)
    assert summary.outcomes[0].kind == "storage" and summary.halted is not None
    assert "executor error: RuntimeError: worker died" in summary.halted


@pytest.mark.parametrize("name", ["..", "../x", "/abs"])
def test_no_suite_name_places_results_outside_the_results_root(tmp_path: Path, name: str) -> None:
    with pytest.raises(BenchError, match="outside"):
        bench_results_root(tmp_path / "results", name)
    assert bench_results_root(tmp_path / "results", "quick") == tmp_path / "results" / "quick"


# -- limits -------------------------------------------------------------------------------------------------------

HOG = "block = bytearray(0)\nwhile True:\n    block += bytearray(8 * 2**20)\n    block[-1] = 1\n"


def _supervised(code: str, time_s: float, memory_mb: float) -> tuple[str | None, float, int]:
    proc = subprocess.Popen([sys.executable, "-c", code])

    def ended(timeout: float) -> bool:
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            return False
        return True

    stop, peak = supervise(watch(proc.pid), ended, time_s, memory_mb)
    return stop, peak, proc.wait()


def test_the_memory_limit_kills_a_cell_whose_resident_memory_passes_it() -> None:
    stop, peak, code = _supervised(HOG, 60, 200)
    assert stop == "memory" and code == -signal.SIGKILL
    assert 200 < peak < 1024  # the overshoot is what 50 ms of allocation adds


def test_the_time_limit_kills_a_cell_that_runs_too_long() -> None:
    stop, _, code = _supervised("import time; time.sleep(60)", 0.5, 1024)
    assert stop == "timeout" and code == -signal.SIGKILL


def test_a_cell_within_its_limits_ends_by_itself() -> None:
    stop, peak, code = _supervised("import sys; sys.exit(3)", 60, 1024)
    assert stop is None and code == 3 and peak >= 0


def test_a_dead_forkserver_is_told_apart_from_a_live_one() -> None:
    server = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        process = psutil.Process(server.pid)
        assert _server_fate(process, wait_s=0.1) is None
        os.kill(server.pid, signal.SIGKILL)
        assert _server_fate(process) == "was killed by SIGKILL"  # read without reaping it ...
        assert server.wait(timeout=5) == -signal.SIGKILL  # ... so its owner still can
        assert _server_fate(process) == "is gone"
    finally:
        server.kill()
        server.wait()


def test_the_file_system_state_names_a_full_or_read_only_results_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real = os.statvfs(tmp_path)

    def fake(**changes: int) -> object:
        fields = {name: getattr(real, name) for name in ("f_flag", "f_bavail", "f_frsize", "f_favail", "f_files")}
        return type("Stat", (), {**fields, **changes})()

    monkeypatch.setattr(os, "statvfs", lambda path: fake(f_bavail=0))
    assert job.file_system_state(tmp_path) == "no space left on device (0.0 MiB free)"
    monkeypatch.setattr(os, "statvfs", lambda path: fake(f_favail=0, f_files=100))
    assert job.file_system_state(tmp_path) == "no space left on device (no free inodes)"
    monkeypatch.setattr(os, "statvfs", lambda path: fake(f_flag=os.ST_RDONLY))
    assert job.file_system_state(tmp_path) == "read-only file system"


def test_a_cell_tells_ctrl_c_from_a_keyboard_interrupt_raised_in_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A plugin raising KeyboardInterrupt was recorded as 'interrupted (SIGINT, e.g. Ctrl-C)'."""
    monkeypatch.setattr(cell_main._Sigint, "watched", False)
    monkeypatch.setattr(cell_main._Sigint, "received", False)
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        cell_main._note_sigint()
        assert cell_main._report(tmp_path, KeyboardInterrupt()) == cell_main.EXIT_EXCEPTION
        raised = json.loads((tmp_path / cell_main.ERROR_FILE).read_text())
        assert (raised["kind"], raised["type"], raised["message"]) == (
            "exception",
            "KeyboardInterrupt",
            "raised in the cell without a Ctrl-C (no SIGINT reached it): by the method?",
        )
        with pytest.raises(KeyboardInterrupt) as caught:
            os.kill(os.getpid(), signal.SIGINT)  # what Ctrl-C does
            time.sleep(5)  # the handler raises at the next bytecode
        assert cell_main._report(tmp_path, caught.value) == cell_main.EXIT_INTERRUPTED
        assert json.loads((tmp_path / cell_main.ERROR_FILE).read_text())["kind"] == "interrupted"
    finally:
        signal.signal(signal.SIGINT, before)


def test_a_damaged_done_folder_is_said_and_its_cell_run_again_while_a_sound_one_is_kept(tmp_path: Path) -> None:
    """The runner used to count a DONE folder with a torn result.json as kept; the report then failed on it forever."""
    store = ResultsStore(tmp_path)
    for key in ("k0", "k1"):
        write_complete_run(store.runs / key, key)
    torn = store.runs / "k1" / "result.json"
    torn.write_text(torn.read_text()[:30])
    ran: list[str] = []

    def job(cell: Cell, root: str) -> CellOutcome:
        ran.append(cell.key)
        write_complete_run(store.runs / cell.key, cell.key)
        return CellOutcome.of(cell, "done", 1.0)

    with cf.ThreadPoolExecutor(max_workers=1) as pool:
        summary = run_grid(plan_of([make_cell("k0"), make_cell("k1")]), store, pool, job=job)
    assert ran == ["k1"] and [o.status for o in summary.outcomes] == ["cached", "done"]
    assert len(summary.damaged) == 1 and summary.damaged[0].startswith(f"{torn}: cannot read a ResultRecord: ")
    assert store.is_complete("k1")
