"""A run's key names the versions of the libraries it computes with, and a run records the versions it was keyed by.

Why: the key named the code, config, data and seed but no library, so after an upgrade of numpy, kiss-icp, gtsam
or MRPT `albot1 bench` kept ("already complete (kept)") results computed with the old library, and the report
labelled them with the new versions of its plan.
"""

from __future__ import annotations

import json
import os
import stat
import sys
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from albot1 import versions
from albot1.bench import job
from albot1.bench import plan as plan_module
from albot1.bench.cells import execute_cell
from albot1.bench.errors import BenchError
from albot1.bench.external import dataset_stem
from albot1.bench.grid import Cell, GridPlan
from albot1.bench.plan import plan_suite
from albot1.bench.runner import kept_failure
from albot1.bench.store import ResultsStore
from albot1.bench.suite import load_suite
from albot1.data.loaders.registry import writer_for
from albot1.data.open import open_sequence
from albot1.data.trajectory import write_tum
from albot1.methods.registry import resolve_config
from albot1.settings import Settings

WORLD = "synthetic-office-startstop[:12]"


def _plan(tmp_path: Path, method: str = "odometry", datasets: tuple[str, ...] = (WORLD,)) -> GridPlan:
    suite = tmp_path / "tiny.toml"
    entries = "".join(f'\n[[datasets]]\nname = "{name}"\nsweep = false\n' for name in datasets)
    suite.write_text(f'[[methods]]\nname = "{method}"\n{entries}')
    return plan_suite(load_suite(suite), Settings(data_dir=None, cache_dir=tmp_path / "cache"))


def _cell(tmp_path: Path, method: str = "odometry") -> Cell:
    [cell] = _plan(tmp_path, method).cells
    return cell


def _with_library(monkeypatch: pytest.MonkeyPatch, name: str, version: str | None) -> None:
    """This process sees ``version`` of ``name`` from now on, as a fresh process would after an upgrade."""
    real = versions.library_versions

    def upgraded(names: tuple[str, ...] = versions.RECORDED_LIBRARIES) -> dict[str, str | None]:
        return {**real(names), **({name: version} if name in names else {})}

    monkeypatch.setattr(versions, "library_versions", upgraded)


def test_a_cell_planned_under_another_version_of_any_recorded_library_gets_another_key(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    before = _cell(tmp_path)
    assert _cell(tmp_path).key == before.key  # nothing changed: the stored run is found again
    upgraded: dict[str, Cell] = {}
    for name in versions.RECORDED_LIBRARIES:
        with monkeypatch.context() as patch:
            _with_library(patch, name, "0.0.1-upgraded")
            upgraded[name] = _cell(tmp_path)
    keys = {before.key} | {cell.key for cell in upgraded.values()}
    assert len(keys) == 1 + len(versions.RECORDED_LIBRARIES)  # each library's upgrade: a key of its own
    assert all(cell.versions[name] == "0.0.1-upgraded" for name, cell in upgraded.items())
    assert _cell(tmp_path).key == before.key  # and back to what was installed: the old key again


def test_the_commit_label_alone_does_not_change_the_key(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The code digest names the code; ``git`` (``-dirty`` after an edit of README.md's neighbours) is a label."""
    before = _cell(tmp_path)
    monkeypatch.setattr(versions, "git_commit", lambda: "v9-9-gdeadbeef-dirty")
    after = _cell(tmp_path)
    assert after.key == before.key and "git" not in after.versions


def test_a_cell_records_the_versions_its_key_was_made_from(tmp_path: Path) -> None:
    cell = _cell(tmp_path)
    run_dir = execute_cell(cell, tmp_path / "runs")
    assert run_dir.name == cell.key
    recorded = json.loads((run_dir / "result.json").read_text())["versions"]
    assert versions.key_versions(recorded) == cell.versions
    assert set(versions.RECORDED_LIBRARIES) <= cell.versions.keys() and cell.versions["code"] == cell.code_version


def test_a_run_with_other_versions_than_planned_is_refused_naming_them(tmp_path: Path) -> None:
    """A library installed while the grid ran (or a worker with another install): not stored under the planned key."""
    cell = _cell(tmp_path)
    planned = replace(cell, versions={**cell.versions, "numpy": "0.0.1-planned"})
    real = cell.versions["numpy"]
    with pytest.raises(BenchError, match=rf"numpy: planned '0.0.1-planned', ran '{real}'"):
        execute_cell(planned, tmp_path / "runs")
    assert not (tmp_path / "runs" / cell.key).exists()


#: A stand-in for MRPT's applications (its banner names MRPT ``FAKE_MRPT_VERSION``).
FAKE_APP = Path(__file__).parents[1] / "methods" / "baselines" / "mrpt" / "fake_mrpt_app.py"


def _mrpt_installed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, version: str) -> Path:
    """MRPT ``version``'s applications first on PATH (new files, as an upgrade installs); returns their start log."""
    bin_dir = tmp_path / f"mrpt-{version}"
    bin_dir.mkdir()
    started = tmp_path / f"started-{version}.txt"
    for app in ("icp-slam", "rbpf-slam"):
        script = bin_dir / app
        script.write_text(
            f'#!/bin/sh\necho "$@" >> "{started}"\nexport FAKE_MRPT_VERSION={version}\n'
            f'exec "{sys.executable}" "{FAKE_APP}" {app} "$@"\n'
        )
        script.chmod(script.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setenv("PATH", f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    return started


@pytest.mark.parametrize("method", ["mrpt-icp", "mrpt-rbpf"])
def test_an_mrpt_cell_planned_under_another_mrpt_gets_another_key(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, method: str
) -> None:
    two = (WORLD, "synthetic-office-startstop[:10]")
    _mrpt_installed(tmp_path, monkeypatch, "2.5.8")
    before = _plan(tmp_path, method, two)
    started = _mrpt_installed(tmp_path, monkeypatch, "2.6.0")
    after = _plan(tmp_path, method, two)
    assert len(after.cells) >= 2 and not {c.key for c in before.cells} & {c.key for c in after.cells}
    assert {c.versions["mrpt"] for c in before.cells} == {"2.5.8"} and before.machine["libraries"]["mrpt"] == "2.5.8"
    assert {c.versions["mrpt"] for c in after.cells} == {"2.6.0"}
    assert after.machine["libraries"]["mrpt"] == "2.6.0"  # what the report says the results were computed with
    assert started.read_text() == "\n"  # started once per plan, with no arguments (its banner), not once per cell


def test_a_method_without_programs_has_no_program_version_in_its_key(tmp_path: Path) -> None:
    plan = _plan(tmp_path)
    assert "mrpt" not in plan.cells[0].versions and "mrpt" not in plan.machine["libraries"]


def _external_plan(tmp_path: Path, dataset: str) -> GridPlan:
    """A suite scoring another system's trajectory file for ``dataset`` (its odometry, as a TUM file)."""
    sequence = open_sequence(dataset)
    tum = tmp_path / "theirs" / f"{dataset_stem(dataset)}.tum"
    tum.parent.mkdir(exist_ok=True)
    write_tum(tum, sequence.arrays.timestamps, sequence.arrays.odometry)
    suite = tmp_path / "theirs.toml"
    suite.write_text(
        f'[[methods]]\nname = "theirs"\ntrajectories = "theirs/{{dataset}}.tum"\n\n[[datasets]]\nname = "{dataset}"\n'
    )
    return plan_suite(load_suite(suite), Settings(data_dir=None, cache_dir=tmp_path / "cache"))


def test_an_external_cell_is_keyed_by_the_libraries_that_score_it_and_records_them(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """It runs no method, but reading the log and computing its metrics (numpy, scipy, shapely...) are the result."""
    [cell] = _external_plan(tmp_path, WORLD).cells
    with monkeypatch.context() as patch:
        _with_library(patch, "scipy", "0.0.1-upgraded")
        [upgraded] = _external_plan(tmp_path, WORLD).cells
    assert upgraded.key != cell.key
    run_dir = execute_cell(cell, tmp_path / "runs")
    assert run_dir.name == cell.key
    recorded = json.loads((run_dir / "result.json").read_text())["versions"]
    assert versions.key_versions(recorded) == cell.versions and set(versions.RECORDED_LIBRARIES) <= recorded.keys()


def test_an_external_cell_is_scored_again_when_the_log_it_is_scored_against_changed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Its reference poses and relations come from the log: an edited log is another result (its checksum keyed)."""
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "checksum-cache"))
    log = tmp_path / "w.clf"
    writer_for("carmen").write(open_sequence(WORLD), log)
    [cell] = _external_plan(tmp_path, str(log)).cells
    run_dir = execute_cell(cell, tmp_path / "runs")
    assert run_dir.name == cell.key
    lines = log.read_text().splitlines(keepends=True)
    index = next(i for i, line in enumerate(lines) if line.startswith("ROBOTLASER1"))
    fields = lines[index].split(" ")
    fields[9] = f"{float(fields[9]) + 0.5:.3f}"  # one range: the same scans, stamps and poses otherwise
    lines[index] = " ".join(fields)
    log.write_text("".join(lines))
    [edited] = _external_plan(tmp_path, str(log)).cells
    assert edited.key != cell.key


def test_a_dask_worker_with_another_library_runs_no_cell_and_says_which(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """As for a worker with other code: the grid halts before a worker computes what the cells' keys do not name."""
    cell = _cell(tmp_path)
    monkeypatch.setattr(job, "_dask_worker", lambda: SimpleNamespace(address="tcp://10.0.0.7:4000"))
    assert job._worker_code_mismatch(cell) is None  # the same install as the planner's
    _with_library(monkeypatch, "gtsam", "9.9")
    outcome = job.run_cell_job(cell, str(tmp_path / "results"))
    assert (outcome.status, outcome.kind, outcome.halts_grid) == ("failed", "executor", True)
    assert outcome.reason is not None and outcome.reason.endswith(
        f"has gtsam 9.9 (planned with {cell.versions['gtsam']}); install the same library versions on every worker"
    )


def test_a_run_refused_for_other_versions_is_no_allowed_method_failure_and_is_not_kept(tmp_path: Path) -> None:
    """The refusal is the environment's fault (another MRPT on a worker, an upgrade mid-grid), not the method's.

    Recorded as the method's own error (kind ``exception``) it was allowed by ``allow_failure`` (``albot1 bench``
    exited 0 with MRPT "failing") and kept on every later run with the same plan, even once the install was fixed.
    """
    cell = replace(_cell(tmp_path), allow_failure=True)
    planned = replace(cell, versions={**cell.versions, "numpy": "0.0.1-planned"})
    outcome = job.run_cell_job(planned, str(tmp_path / "results"))
    assert (outcome.status, outcome.kind, outcome.allowed) == ("failed", "executor", False)
    assert outcome.reason is not None and "numpy: planned '0.0.1-planned'" in outcome.reason
    assert kept_failure(ResultsStore(tmp_path / "results"), planned) is None  # the next run tries it again


def test_an_entry_whose_config_cannot_be_resolved_leaves_the_other_entries_of_its_method_alone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The program versions are read once per method, but a config problem is one entry's, not every entry's.

    They were read per method with the problem of whichever entry of it came last, so a broken second entry
    (a config model raising for its ``set``) failed the first entry's cells with its reason and left their keys
    without the program versions their runs record.
    """
    real = resolve_config

    def broken_for_overrides(method: str, preset: str, overrides: dict[str, Any], *args: Any, **kwargs: Any) -> Any:
        if overrides:
            raise RuntimeError("the config model fails on this entry's settings")
        return real(method, preset, overrides, *args, **kwargs)

    monkeypatch.setattr(plan_module, "resolve_config", broken_for_overrides)
    suite = tmp_path / "two.toml"
    suite.write_text(
        '[[methods]]\nname = "kiss-icp"\n\n[[methods]]\nname = "kiss-icp"\nlabel = "kiss-icp-wide"\n'
        f'set = {{ voxel_size_m = 0.3 }}\n\n[[datasets]]\nname = "{WORLD}"\nsweep = false\n'
    )
    plan = plan_suite(load_suite(suite), Settings(data_dir=None, cache_dir=tmp_path / "cache"))
    failing = {cell.method_label for cell in plan.cells if cell.key in plan.config_failures}
    assert failing == {"kiss-icp-wide"}
