"""The disk fills up mid-grid: the cell is recorded with "no space left", the runner stops, nothing is lost.

A real 2 MiB tmpfs holds the results (about four cells of dead reckoning
on the 106-view world, of the grid's eleven); the test skips with its reason where it may not
mount one (not root, no ``mount``). The unit tests of
``tests/unit/bench/test_bench_failures.py`` inject ENOSPC without a mount.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from albot1.bench.store import ResultsStore

# `albot1 bench` end to end (its grid in worker processes): the end-to-end lane (Makefile, `make test-end-to-end`)
pytestmark = pytest.mark.end_to_end

WORLD = "synthetic-office-startstop"
SUITE = f"""
[grid]
degradations = ["gauss:0.1:1"]
seeds = [{", ".join(str(s) for s in range(10))}]

[[methods]]
name = "odometry"

[[datasets]]
name = "{WORLD}"
"""


@pytest.fixture
def tiny_disk(tmp_path: Path) -> Iterator[Path]:
    """2 MiB: full after about four cells, with about five of the eleven not started (measured 2026-11-27).

    Every cell the first run does not complete is run by the second, so cells beyond those the disk holds,
    the running ones (-j 2) and a few left unstarted only cost time: the grid had 21 cells before.
    """
    mount = tmp_path / "disk"
    mount.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a 2 MiB tmpfs needs root and the mount command")
    done = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(mount)], capture_output=True, text=True
    )
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.strip()}")
    try:
        yield mount
    finally:
        subprocess.run(["umount", "-l", str(mount)], check=False)


def bench(suite: Path, results: Path) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-c", "from albot1.cli.app import main; main()", "bench", str(suite)]
    command += ["-j", "2", "--results", str(results), "--no-progress"]
    return subprocess.run(command, capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_a_full_disk_stops_the_grid_loses_nothing_and_a_later_run_resumes(tmp_path: Path, tiny_disk: Path) -> None:
    suite = tmp_path / "disk.toml"
    suite.write_text(SUITE)
    first = bench(suite, tiny_disk)
    assert first.returncode == 1, first.stderr
    assert "Traceback" not in first.stderr
    assert "total" in first.stdout  # the summary was printed
    halted = [line for line in first.stderr.splitlines() if line.startswith("halted: ")]
    assert len(halted) == 1 and "no space left on device" in halted[0], first.stderr
    assert "cells not started" in halted[0] and "run the same command again to resume" in halted[0]

    store = ResultsStore(tiny_disk / "disk")
    plan = store.read_plan()
    complete = {c.key for c in plan.cells if store.is_complete(c.key)}
    failed = {c.key: store.failure(c.key) for c in plan.cells if store.failure(c.key) is not None}
    assert complete and failed and len(complete) + len(failed) < len(plan.cells)
    assert all(f.kind == "storage" and "no space left on device" in f.reason for f in failed.values() if f)
    # A cell that completed just as the disk filled stays complete with only its attempt record missing (by
    # design: albot1.bench.job; its outcome halts the grid): at most one such cell per running job (-j 2).
    no_attempt = [key for key in complete if not (store.run_dir(key) / "attempt.json").exists()]
    assert len(no_attempt) <= 2, no_attempt
    for key in complete:  # complete cells are whole: every file, no temporary or empty file
        folder = store.run_dir(key)
        names = {p.name for p in folder.iterdir()}
        assert {"DONE", "metrics.json", "result.json", "per_scan_ns.npy"} <= names
        assert not [n for n in names if n.startswith(".")], names
        assert all(p.stat().st_size > 0 for p in folder.iterdir()), names
        json.loads((folder / "metrics.json").read_text())
    for key in failed:  # the failed attempt's files were removed to make room for its record
        assert sorted(p.name for p in store.run_dir(key).iterdir()) == ["FAILED.json", "cell.json", "cell.log"]
    stamps = {key: (store.run_dir(key) / "metrics.json").stat().st_mtime_ns for key in complete}

    subprocess.run(["mount", "-o", "remount,size=16m", str(tiny_disk)], check=True)
    second = bench(suite, tiny_disk)
    assert second.returncode == 0, second.stderr
    assert f"{len(complete)} of {len(plan.cells)} cells already complete (kept)" in second.stderr
    assert all(store.is_complete(c.key) for c in plan.cells)
    assert {key: (store.run_dir(key) / "metrics.json").stat().st_mtime_ns for key in complete} == stamps
    assert not any(store.run_dir(c.key).joinpath("FAILED.json").exists() for c in plan.cells)
