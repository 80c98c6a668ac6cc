"""Hand-edited store files are read through typed records; a disk full at start names the file."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path
from typing import Any

import pytest

from albot1.bench import store as store_module
from albot1.bench.errors import BenchError
from albot1.bench.grid import Cell, GridPlan
from albot1.bench.plan import plan_suite
from albot1.bench.store import UNREADABLE_FAILURE, ResultsStore
from albot1.bench.suite import load_suite
from albot1.data.loaders.registry import writer_for
from albot1.data.open import open_sequence
from albot1.records import AttemptRecord, RecordError, read_record
from albot1.settings import Settings

KEY = "0123456789abcdef"


def cell(key: str = KEY) -> Cell:
    return Cell("s", "w", "w", "odometry", "odometry", "default", "none", 0, key, "v", 10.0, 100.0)


def plan_json(**changes: Any) -> dict[str, Any]:
    plan = GridPlan("s", None, "", [cell()], [], [], {}, [0], ["none"], {"cpu_count": 2})
    return {**plan.to_json(), **changes}


def write_plan(tmp_path: Path, data: Any) -> Path:
    (tmp_path / "grid.json").write_text(json.dumps(data))
    return tmp_path / "grid.json"


def test_a_valid_plan_reads_back() -> None:
    assert GridPlan.from_json(plan_json()).cells == [cell()]


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"cells": "x"}, "cells: Input should be a valid list"),
        ({"machine": "x"}, "machine: Input should be a valid dictionary"),
        ({"seeds": ["a"]}, "seeds.0: Input should be a valid integer"),
        ({"cells": [{**cell().to_json(), "seed": "abc"}]}, "cells.0.seed: Input should be a valid integer"),
        ({"cells": [{"suite": "s"}]}, "cells.0.dataset: Field required"),
    ],
)
def test_a_hand_edited_grid_is_one_error_naming_file_and_field(
    tmp_path: Path, changes: dict[str, Any], field: str
) -> None:
    path = write_plan(tmp_path, plan_json(**changes))
    with pytest.raises(RecordError) as caught:
        ResultsStore(tmp_path).read_plan()
    assert str(caught.value).startswith(f"{path}: not a grid plan written by `albot1 bench`: {field}")


@pytest.mark.parametrize("key", ["../../../../etc", "k1", "0123456789ABCDEF", "0123456789abcdef0"])
def test_a_cell_key_that_is_not_a_run_key_is_refused(tmp_path: Path, key: str) -> None:
    path = write_plan(tmp_path, plan_json(cells=[cell(key).to_json()]))
    with pytest.raises(RecordError) as caught:
        ResultsStore(tmp_path).read_plan()
    assert (
        str(caught.value)
        == f"{path}: cells.0.key: {key!r} is not a cell key; expected 16 hex digits (a run folder name)"
    )


@pytest.mark.parametrize("data", ["[1, 2]", "{", '"x"'])
def test_a_grid_that_is_no_object_is_refused(tmp_path: Path, data: str) -> None:
    (tmp_path / "grid.json").write_text(data)
    with pytest.raises(RecordError, match=r"grid\.json: not a grid plan written by `albot1 bench`"):
        ResultsStore(tmp_path).read_plan()


def test_a_key_never_leads_out_of_the_runs_folder(tmp_path: Path) -> None:
    with pytest.raises(BenchError, match=r"cell key '\.\./\.\./etc' is not a folder name"):
        ResultsStore(tmp_path).run_dir("../../etc")


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        ({"elapsed_s": "abc"}, "elapsed_s: Input should be a valid number"),
        ({"elapsed_s": -1}, "elapsed_s: Input should be greater than or equal to 0"),
        ({"kind": "boom"}, "kind: Input should be"),
        ({"reason": None}, "reason: Input should be a valid string"),
        ({"surprise": 1}, "surprise: Extra inputs are not permitted"),
        ({"log": "../../../etc/passwd"}, "log: Value error, '../../../etc/passwd' is not a file name of the cell"),
    ],
)
def test_a_hand_edited_failure_record_names_file_and_field(tmp_path: Path, edit: dict[str, Any], field: str) -> None:
    store = ResultsStore(tmp_path)
    store.record_failure(cell(), "boom", "exception", exit_code=2, elapsed_s=1.5)
    path = store.run_dir(KEY) / "FAILED.json"
    path.write_text(json.dumps({**json.loads(path.read_text()), **edit}))
    with pytest.raises(RecordError) as caught:
        store.failure(KEY)
    assert str(caught.value).startswith(f"{path}: not a failure record written by `albot1 bench`: {field}")
    lenient = store.failure(KEY, strict=False)  # the runner retries such a cell, trusting nothing in it
    assert lenient is not None and lenient.reason == UNREADABLE_FAILURE


def test_a_failure_record_reads_back(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path)
    store.record_failure(cell(), "boom", "timeout", exit_code=None, elapsed_s=2.5)
    failure = store.failure(KEY)
    assert failure is not None and (failure.reason, failure.kind, failure.elapsed_s) == ("boom", "timeout", 2.5)


class _FullDisk:
    """A file handle whose writes meet a full disk (as on a file system with no block left)."""

    def __init__(self, handle: Any) -> None:
        self.handle = handle

    def __getattr__(self, name: str) -> Any:
        return getattr(self.handle, name)

    def flush(self) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    def close(self) -> None:
        self.handle.close()
        raise OSError(errno.ENOSPC, "No space left on device")


def test_a_disk_full_when_the_bench_starts_names_the_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real_open = open
    monkeypatch.setattr(store_module, "open", lambda *a, **k: _FullDisk(real_open(*a, **k)), raising=False)
    with pytest.raises(OSError) as caught:
        ResultsStore(tmp_path / "s").lock()
    assert (caught.value.errno, caught.value.filename) == (errno.ENOSPC, str(tmp_path / "s" / ".lock"))


def test_a_cell_key_names_the_data_content(tmp_path: Path) -> None:
    log = tmp_path / "t.clf"
    writer_for("carmen").write(open_sequence("synthetic-office-startstop[:20]"), log)
    suite = tmp_path / "s.toml"
    suite.write_text(f'[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "{log}"\n')
    settings = Settings(None, tmp_path / "cache")
    first = plan_suite(load_suite(suite), settings).cells[0].key
    assert plan_suite(load_suite(suite), settings).cells[0].key == first
    text = log.read_text()
    log.write_text(text.replace("FLASER", "FLASER", 1) + "# edited\n")
    assert plan_suite(load_suite(suite), settings).cells[0].key != first


@pytest.mark.timeout(30)
def test_store_files_that_are_fifos_are_refused_without_blocking(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "grid.json")
    with pytest.raises(RecordError) as caught:
        ResultsStore(tmp_path).read_plan()
    assert str(caught.value) == (
        f"{tmp_path / 'grid.json'}: a FIFO (named pipe), not a regular file; expected a grid plan written by "
        "`albot1 bench`"
    )
    store = ResultsStore(tmp_path / "other")
    run_dir = store.prepare(cell())
    (run_dir / "DONE").write_text(KEY)
    os.mkfifo(run_dir / "metrics.json")
    assert not store.is_complete(KEY)  # never read: the cell is run again
    os.mkfifo(run_dir / "attempt.json")
    with pytest.raises(RecordError, match=r"attempt\.json: a FIFO \(named pipe\), not a regular file; expected a"):
        read_record(AttemptRecord, run_dir / "attempt.json")
