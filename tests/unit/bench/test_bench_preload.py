"""The forkserver preload: a failed import is reported once, by name, never swallowed."""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

from albot1.bench.limits import METHODS_ENV as ENV


@pytest.fixture
def preload() -> ModuleType:
    """The preload module, imported when a test runs rather than at collection (importing it preloads every method)."""
    from albot1.bench import preload

    return preload


def test_a_failed_import_is_returned_with_module_and_reason(preload: ModuleType) -> None:
    failures = preload.warm(["json", "albot1_no_such_module_xyz"])
    assert [f for f in failures if "albot1_no_such_module_xyz" in f] == [
        "module albot1_no_such_module_xyz: ModuleNotFoundError: No module named 'albot1_no_such_module_xyz'"
    ]
    assert not any(f.startswith("module json") for f in failures)


def test_the_shipped_list_imports_cleanly(preload: ModuleType) -> None:
    assert [f for f in preload.warm() if f.startswith("module ")] == []


def test_the_methods_warm_up_failures_are_returned_with_the_import_failures(
    preload: ModuleType, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each method's failed warm-up and a joint-only failure reach the runner's warning lines, in that order."""
    from albot1.methods import warm_ups

    seen: list[list[str]] = []

    def warm_up_methods(methods: list[str], registry: object = None, announce: object = None) -> object:
        seen.append(list(methods))
        return warm_ups.WarmUpOutcome(failures=["method odometry: warm-up: E: x"], joint_failure="methods odometry: j")

    monkeypatch.setattr(warm_ups, "warm_up_methods", warm_up_methods)
    failures = preload.warm([], methods=frozenset({"odometry"}))
    assert seen == [["odometry"]]
    assert failures[-2:] == ["method odometry: warm-up: E: x", "methods odometry: j"]


def test_a_name_no_method_has_is_said(
    preload: ModuleType, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """``ALBOT1_PRELOAD_METHODS=bogus`` preloaded nothing without a word (every cell then warmed up alone)."""
    from albot1.methods import warm_ups
    from albot1.methods.registry import method_registry

    monkeypatch.setattr(warm_ups, "warm_up_methods", lambda *a, **k: warm_ups.WarmUpOutcome(failures=[]))
    with caplog.at_level(logging.WARNING, logger=preload.__name__):
        preload.warm([], methods=frozenset({"odometry", "kiss icp", "bogus"}))
        preload.warm([], methods=frozenset({"odometry"}))
    names = ", ".join(spec.name for spec in method_registry())
    assert [r.getMessage() for r in caplog.records] == [
        "albot1 bench: ALBOT1_PRELOAD_METHODS names no registered method: 'bogus', 'kiss icp' "
        f"(nothing preloaded for it); expected names from: {names}"
    ]


def test_failures_are_logged_once_each(
    preload: ModuleType, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    monkeypatch.setattr(preload, "warm", lambda methods=None: ["module x: ImportError: boom"])
    monkeypatch.setattr(preload, "_warm_matplotlib", lambda: None)
    with caplog.at_level(logging.WARNING, logger=preload.__name__):
        preload._warm()
    assert [r.getMessage() for r in caplog.records] == [
        "albot1 bench: preloading module x: ImportError: boom (each cell that needs it will fail with this reason)"
    ]


_FORKED_CELL = """
import json
import albot1.bench.preload  # what the forkserver imports before it forks any cell
from albot1.methods.registry import get_method, resolve_config
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.warm_up import kernel_names

mapper = get_method("albot1").load_class()(resolve_config("albot1", "plus", None))
counts = {name: len(getattr(k, name).signatures) for k in mapper.kernels for name in kernel_names(k)}
# plus never calls MappingKernels.FUSED on their own: perceive compiles them into itself
print(json.dumps({name: n for name, n in counts.items() if name not in MappingKernels.FUSED}))
"""


@pytest.mark.slow
@pytest.mark.compile
def test_the_forkserver_compiles_every_kernel_before_any_cell_is_forked() -> None:
    """A cell forked after the preload finds every Albot1 kernel compiled: its start-up compiles nothing."""
    import json

    out = subprocess.run(
        [sys.executable, "-c", _FORKED_CELL], env=dict(os.environ), capture_output=True, text=True, timeout=900
    )
    assert out.returncode == 0, out.stderr
    counts = json.loads(out.stdout)
    assert counts and all(n >= 1 for n in counts.values()), counts


def test_the_methods_to_preload_are_every_method_unless_named(
    preload: ModuleType, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv(preload.METHODS_ENV, raising=False)
    assert preload.methods_to_preload() is None
    monkeypatch.setenv(preload.METHODS_ENV, " odometry, fault ,,")
    assert preload.methods_to_preload() == {"odometry", "fault"}
    monkeypatch.setenv(preload.METHODS_ENV, "")
    assert preload.methods_to_preload() == frozenset()


def test_the_server_is_started_with_the_grid_s_methods_named_and_the_environment_restored(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from albot1.bench import limits

    seen: list[str | None] = []
    monkeypatch.setattr("multiprocessing.forkserver.ensure_running", lambda: seen.append(os.environ.get(ENV)))
    monkeypatch.setattr(limits, "launcher", lambda: "forkserver")
    monkeypatch.setenv(ENV, "before")
    limits.start_forkserver({"odometry", "albot1"})
    limits.start_forkserver(None)
    monkeypatch.delenv(ENV)
    limits.start_forkserver(["kiss-icp"])
    assert seen == ["albot1,odometry", "before", "kiss-icp"]
    assert ENV not in os.environ


_PRELOADED = """
import sys
import albot1.bench.preload
print(" ".join(sorted(m for m in ("albot1.methods.baselines.odometry", "albot1.methods.albot1.mapping.mapper",
                                  "albot1.methods.baselines.kiss_icp") if m in sys.modules)))
"""


def test_a_server_told_one_method_imports_that_one_only() -> None:
    """What ALBOT1_PRELOAD_METHODS saves: the other methods' imports and warm-ups (run in a fresh interpreter)."""
    env = dict(os.environ, **{ENV: "odometry"})
    out = subprocess.run([sys.executable, "-c", _PRELOADED], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["albot1.methods.baselines.odometry"]


class _Planned(Exception):
    """Raised in place of planning: the test only looks at how the server was started."""


@pytest.mark.parametrize(
    ("methods", "preloaded"),
    [
        ('[[methods]]\nname = "odometry"\n\n[[methods]]\nname = "kiss-icp"\n', {"odometry", "kiss-icp"}),
        ('registered_methods = true\n\n[[methods]]\nname = "odometry"\n', None),
        # a name no method has is the planner's error to give: named to the server too, it logged a second, puzzling
        # warning about ALBOT1_PRELOAD_METHODS, a variable the user never set
        ('[[methods]]\nname = "odometry"\n\n[[methods]]\nname = "nosuch"\n', {"odometry"}),
    ],
)
def test_the_runner_starts_the_server_with_the_suite_s_methods(
    methods: str, preloaded: set[str] | None, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from albot1.bench import runner

    suite = tmp_path / "small.toml"
    suite.write_text(methods + '\n[[datasets]]\nname = "synthetic-office-loop"\n')
    started: list[object] = []
    monkeypatch.setattr(runner, "start_forkserver", started.append)
    monkeypatch.setattr(runner, "plan_suite", lambda *_: (_ for _ in ()).throw(_Planned()))
    with pytest.raises(_Planned):
        runner.run_suite(str(suite), results=tmp_path / "results")
    assert started == [preloaded]


def test_cell_threads_starting_the_server_at_once_leave_the_environment_as_it_was(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Every cell thread calls start_forkserver with its method; the changes must not interleave and leak."""
    import threading
    import time

    from albot1.bench import limits

    seen: list[str | None] = []

    def ensure_running() -> None:
        seen.append(os.environ.get(ENV))
        time.sleep(0.01)  # long enough for another thread to change the variable if it could

    monkeypatch.setattr("multiprocessing.forkserver.ensure_running", ensure_running)
    monkeypatch.setattr(limits, "launcher", lambda: "forkserver")
    monkeypatch.delenv(ENV, raising=False)
    threads = [threading.Thread(target=limits.start_forkserver, args=([f"m{i}"],)) for i in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert sorted(seen) == [f"m{i}" for i in range(8)]
    assert ENV not in os.environ


_COLLECTED = """
import gc
import json

import albot1.bench.preload  # what the forkserver imports before it forks any cell
print(json.dumps({"count": gc.get_count(), "garbage": gc.collect()}))
"""


def test_the_server_leaves_no_garbage_and_no_collection_due_for_its_cells() -> None:
    """A forked cell inherits the server's collector: nothing to free and generation 2 not due (issue 24)."""
    import json

    env = dict(os.environ, **{ENV: "odometry"})
    out = subprocess.run([sys.executable, "-c", _COLLECTED], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    state = json.loads(out.stdout)
    assert state["garbage"] == 0
    assert state["count"][1:] == [0, 0]


def test_a_forkserver_child_freezes_what_it_inherited_before_it_runs_the_cell(monkeypatch: pytest.MonkeyPatch) -> None:
    """Its collections then walk only what the cell allocates, never the server's heap (issue 24)."""
    import gc

    from albot1.bench import cell_main

    order: list[str] = []
    monkeypatch.setattr(gc, "freeze", lambda: order.append("freeze"))  # this test process is left as it is
    monkeypatch.setattr(cell_main, "child_main", lambda args: order.append(f"cell {args['cell']}") or 0)
    with pytest.raises(SystemExit) as ended:
        cell_main.process_entry({"cell": "k"})
    assert ended.value.code == 0
    assert order == ["freeze", "cell k"]


_VERSIONS_IN_A_CELL = """
import json
import subprocess
from importlib import metadata

import albot1.bench.preload  # what the forkserver imports before it forks any cell
from albot1 import versions


def refuse(*args: object, **kwargs: object) -> None:
    raise AssertionError(f"called in the cell: {args}")


subprocess.run = refuse  # no `git` command ...
metadata.version = refuse  # ... and no search of the installed distributions in the cell
print(json.dumps([versions.git_commit(), versions.library_versions()]))
"""


def test_a_cell_inherits_the_commit_and_library_versions_its_run_records() -> None:
    """The preload reads them once (git_commit, library_versions); a cell then starts no `git` and reads no metadata."""
    from albot1 import versions

    env = dict(os.environ, **{ENV: ""})  # no method preloaded: only the versions matter here
    out = subprocess.run(
        [sys.executable, "-c", _VERSIONS_IN_A_CELL], env=env, capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    versions.git_commit.cache_clear()
    assert json.loads(out.stdout) == [versions.git_commit(), versions.library_versions()]


_CELL_IMPORTS = """
import json
import sys
import tempfile
from pathlib import Path

import albot1.bench.preload  # what the forkserver imports before it forks any cell
from albot1.bench.cells import execute_cell
from albot1.bench.grid import Cell
from albot1.bench.plan import plan_suite
from albot1.bench.suite import load_suite
from albot1.settings import get_settings
from albot1.report.preview import render_preview  # the renderer the runner names; imported by the server's cells

suite = Path(tempfile.mkdtemp()) / "s.toml"
suite.write_text('''
description = "cheap cells"
[limits]
time_s = 60
memory_mb = 2048
[grid]
degradations = ["gauss:0.1:1"]
seeds = [0]
[[methods]]
name = "odometry"
[[methods]]
name = "kiss-icp"
[[datasets]]
name = "synthetic-office-startstop[:12]"
sweep = true
''')
before = set(sys.modules)
for cell in plan_suite(load_suite(suite), get_settings()).cells:
    execute_cell(Cell.from_json(cell.to_json()), Path(tempfile.mkdtemp()), preview=render_preview)
print(json.dumps(sorted(set(sys.modules) - before)))
"""


def test_cheap_cells_import_nothing_the_server_could_have_imported(tmp_path: Path) -> None:
    """Odometry and KISS-ICP cells on a world, run after the server's preload, import no module of their own.

    Each module a cell imports is imported again in every cell (2-14 ms of CPU each in a fork: platformdirs,
    shapely.ops, the cp437 codec zipfile reads .npz member names with, KISS-ICP's modules); imported by the
    server, never (issue 24).
    """
    env = dict(os.environ, **{ENV: "odometry,kiss-icp", "ALBOT1_DECODED_CACHE": str(tmp_path / "decoded")})
    out = subprocess.run([sys.executable, "-c", _CELL_IMPORTS], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout.splitlines()[-1]) == []
