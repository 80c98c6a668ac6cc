"""A cell's wall time starts when its process exists: the forkserver's preload it waited for is recorded apart.

Why: the first cells of a grid are forked by a server still running its
preload (every import and every method's warm-up: 46 s on a cold numba
cache), and their ``attempt.json`` charged that to the method (0.14 s of
its own). The clock here is a fake one that only the stand-ins move, so no
assertion depends on how fast the machine is.
"""

from __future__ import annotations

import json
import types
from collections.abc import Callable, Iterable
from pathlib import Path

import pytest

from albot1.bench import job, limits
from albot1.bench.grid import Cell
from albot1.bench.limits import ChildExit, run_limited
from albot1.bench.store import ATTEMPT, FAILED, ResultsStore
from albot1.records import AttemptRecord, dump_record, parse_record, read_record
from conftest import write_complete_run

PRELOAD_S = 46.0
CELL_S = 0.25


def make_cell() -> Cell:
    return Cell(
        suite="t",
        dataset="w",
        dataset_label="w",
        method="odometry",
        method_label="odometry",
        preset="default",
        degradation="none",
        seed=0,
        key="k1",
        code_version="v",
        time_s=5,
        memory_mb=100,
    )


class FakeClock:
    """``time.monotonic`` of :mod:`albot1.bench.limits`, moved only by the stand-ins below."""

    def __init__(self) -> None:
        self.now = 100.0

    def monotonic(self) -> float:
        return self.now


def fake_forkserver(monkeypatch: pytest.MonkeyPatch, clock: FakeClock) -> None:
    """A forkserver whose preload takes :data:`PRELOAD_S` and whose child runs :data:`CELL_S`, on ``clock``."""

    def preloading(methods: Iterable[str] | None = None) -> None:
        clock.now += PRELOAD_S

    class Child:
        pid = -1

        def __init__(self, target: Callable[..., object], args: tuple[object, ...], name: str) -> None:
            self.runs = True

        def ended(self, timeout: float) -> bool:
            if self.runs:
                clock.now += CELL_S
                self.runs = False
            return True

        def exit_code(self) -> int:
            return 0

        def kill(self) -> None:
            raise AssertionError("a child that ended by itself is not killed")

    monkeypatch.setattr(limits, "time", types.SimpleNamespace(monotonic=clock.monotonic))
    monkeypatch.setattr(limits, "start_forkserver", preloading)
    monkeypatch.setattr(limits, "ForkserverChild", Child)
    monkeypatch.setattr(limits, "watch", lambda pid: None)


def test_the_preload_a_cell_waited_for_is_its_launch_time_not_its_wall(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    clock = FakeClock()
    fake_forkserver(monkeypatch, clock)
    ended = run_limited(make_cell(), tmp_path, tmp_path / "cell.log", how="forkserver")
    assert ended.exit_code == 0
    assert ended.elapsed_s == pytest.approx(CELL_S, abs=1e-9)
    assert ended.launch_s == pytest.approx(PRELOAD_S, abs=1e-9)


def completes_after_a_preload(cell: Cell, runs_root: Path, log_path: Path, **_: object) -> ChildExit:
    write_complete_run(runs_root / cell.key, cell.key)
    return ChildExit(0, False, CELL_S, launch_s=PRELOAD_S)


def test_attempt_json_holds_the_cells_wall_and_its_launch_apart(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(job, "run_limited", completes_after_a_preload)
    outcome = job.run_cell_job(make_cell(), str(tmp_path))
    assert outcome.status == "done" and outcome.elapsed_s == CELL_S
    record = read_record(AttemptRecord, tmp_path / "runs" / "k1" / ATTEMPT)
    assert (record.elapsed_s, record.launch_s) == (CELL_S, PRELOAD_S)


def test_a_failed_cells_record_holds_its_launch_apart(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def crashes(cell: Cell, runs_root: Path, log_path: Path, **_: object) -> ChildExit:
        return ChildExit(-11, False, CELL_S, launch_s=PRELOAD_S)

    monkeypatch.setattr(job, "run_limited", crashes)
    outcome = job.run_cell_job(make_cell(), str(tmp_path))
    assert outcome.status == "failed" and outcome.elapsed_s == CELL_S
    written = json.loads((tmp_path / "runs" / "k1" / FAILED).read_text())
    assert (written["elapsed_s"], written["launch_s"]) == (CELL_S, PRELOAD_S)
    failure = ResultsStore(tmp_path).failure("k1")
    assert failure is not None and failure.elapsed_s == CELL_S


def test_an_attempt_written_before_the_launch_was_recorded_reads_and_writes_back_unchanged() -> None:
    old = {"elapsed_s": 1.5, "host": "h", "finished": "2026-11-27T02:34:00Z"}
    record = parse_record(AttemptRecord, old, "attempt.json")
    assert record.launch_s is None
    assert dump_record(record) == old
