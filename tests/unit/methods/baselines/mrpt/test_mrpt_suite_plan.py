"""Suites and the MRPT methods: only run where named, and "unavailable" (not a failure) without MRPT."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.bench.grid import GridPlan
from albot1.bench.plan import plan_suite
from albot1.bench.suite import load_suite
from albot1.settings import Settings

WORLD = "synthetic-office-startstop"


def _plan(tmp_path: Path, methods: str, registered: bool) -> GridPlan:
    path = tmp_path / "tiny.toml"
    head = "registered_methods = true\n" if registered else ""
    path.write_text(f'{head}[[methods]]\nname = "odometry"\n{methods}\n[[datasets]]\nname = "{WORLD}"\n')
    return plan_suite(load_suite(path), Settings(data_dir=None, cache_dir=tmp_path / "cache"))


def test_registered_methods_do_not_pull_in_the_mrpt_baselines(tmp_path: Path) -> None:
    plan = _plan(tmp_path, "", registered=True)
    planned = {c.method for c in plan.cells} | {s.name for s in plan.skipped_methods}
    assert "odometry" in planned and not planned & {"mrpt-icp", "mrpt-rbpf"}


def test_named_mrpt_methods_without_the_programs_are_skipped_as_unavailable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("PATH", str(tmp_path))  # no icp-slam, no rbpf-slam
    plan = _plan(tmp_path, '[[methods]]\nname = "mrpt-rbpf"\n[[methods]]\nname = "mrpt-icp"\n', registered=False)
    skipped = {s.name: s for s in plan.skipped_methods}
    assert skipped["mrpt-rbpf"].reason == "unavailable: needs the program(s) rbpf-slam, not found on PATH"
    assert skipped["mrpt-icp"].hint == "apt-get install mrpt-apps (or: make mrpt)"
    assert {c.method for c in plan.cells} == {"odometry"}  # the rest of the suite still runs
