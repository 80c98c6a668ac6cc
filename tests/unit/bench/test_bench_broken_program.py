"""A method's program that cannot start is the install's failure, not the method's: never allowed, never kept.

Why: MRPT's applications run with ``allow_failure`` (their divergences, crashes and limits are findings), and a
broken install (a shared library gone: the loader's exit status 127) was recorded as MRPT's own failure, allowed:
``albot1 bench`` exited 0 with every MRPT cell "failed" on the page, and kept those failures on the next run.
"""

from __future__ import annotations

import stat
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from albot1.bench import job, limits
from albot1.bench.grid import Cell
from albot1.bench.plan import plan_suite
from albot1.bench.runner import kept_failure
from albot1.bench.store import ResultsStore
from albot1.bench.suite import load_suite
from albot1.settings import Settings

WORLD = "synthetic-office-startstop[:8]"
FAKE_APP = Path(__file__).parents[1] / "methods" / "baselines" / "mrpt" / "fake_mrpt_app.py"
LOADER = "error while loading shared libraries: libmrpt-slam.so.2.5: cannot open shared object file"


def _install(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, body: str) -> None:
    """``icp-slam`` and ``rbpf-slam`` alone on PATH, each the shell script ``body`` (``$APP`` names it)."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for app in ("icp-slam", "rbpf-slam"):
        script = bin_dir / app
        script.write_text(f"#!/bin/sh\nAPP={app}\n{body}\n")
        script.chmod(script.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setenv("PATH", str(bin_dir))  # alone: not a real MRPT of this machine behind it
    monkeypatch.setenv("FAKE_MRPT_SCANS", "8")
    # each cell a process of its own, with this PATH: a forkserver started by an earlier test keeps that one's
    monkeypatch.setattr(limits, "launcher", lambda: "subprocess")


def _mrpt_cell(tmp_path: Path) -> Cell:
    suite = tmp_path / "tiny.toml"
    suite.write_text(f'[[methods]]\nname = "mrpt-icp"\nallow_failure = true\n[[datasets]]\nname = "{WORLD}"\n')
    [cell] = plan_suite(load_suite(suite), Settings(data_dir=None, cache_dir=tmp_path / "cache")).cells
    assert cell.allow_failure
    return cell


def test_a_program_the_loader_cannot_start_fails_the_cell_as_the_install_s_not_allowed_not_kept(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _install(tmp_path, monkeypatch, f'echo "$APP: {LOADER}" >&2\nexit 127')
    cell = _mrpt_cell(tmp_path)
    outcome = job.run_cell_job(cell, str(tmp_path / "results"))
    assert (outcome.status, outcome.kind, outcome.allowed) == ("failed", "executor", False)
    assert outcome.reason is not None and "icp-slam exited with status 127: it could not start" in outcome.reason
    assert LOADER in outcome.reason
    assert kept_failure(ResultsStore(tmp_path / "results"), cell) is None  # the next run tries it again


def test_a_program_that_runs_and_fails_is_still_the_method_s_own_allowed_failure(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _install(tmp_path, monkeypatch, f'FAKE_MRPT_MODE=crash exec "{sys.executable}" "{FAKE_APP}" "$APP" "$@"')
    cell = _mrpt_cell(tmp_path)
    outcome = job.run_cell_job(cell, str(tmp_path / "results"))
    assert (outcome.status, outcome.kind, outcome.allowed) == ("failed", "exception", True)
    assert outcome.reason is not None and "exited with status 255" in outcome.reason


def test_a_program_gone_after_planning_fails_the_cell_as_the_install_s(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _install(tmp_path, monkeypatch, f'exec "{sys.executable}" "{FAKE_APP}" "$APP" "$@"')
    cell = replace(_mrpt_cell(tmp_path), allow_failure=True)
    (tmp_path / "bin" / "icp-slam").unlink()
    outcome = job.run_cell_job(cell, str(tmp_path / "results"))
    assert (outcome.status, outcome.kind, outcome.allowed) == ("failed", "executor", False)
    assert outcome.reason is not None and "needs the program(s) icp-slam, not found on PATH" in outcome.reason
