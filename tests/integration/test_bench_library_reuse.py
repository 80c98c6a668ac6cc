"""`albot1 bench` keeps a stored result only while the libraries it was computed with are the ones installed.

Why: a run's key named no library, so after an upgrade `albot1 bench` kept every result computed with the
old library ("already complete (kept)") and its report labelled them with the new versions of the plan.

"Installed" here is what the package metadata says, as after a `pip install`: a ``numpy-<version>.dist-info``
put first on the import path (numpy's own modules still load), seen by the planner and by every cell
process. The cells run in fresh processes (the ``subprocess`` launcher, what a Dask worker uses), so that each
bench reads the versions anew as a new `albot1 bench` does; the default forkserver reads them the same way,
after its imports (``albot1.bench.preload``; ``test_bench_preload`` checks it records what a fresh process does).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from albot1 import versions
from albot1.bench import limits
from albot1.cli.app import app

# `albot1 bench` end to end (its cells in worker processes): the end-to-end lane (Makefile, `make test-end-to-end`)
pytestmark = pytest.mark.end_to_end

SUITE = '[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "synthetic-office-startstop[:12]"\nsweep = false\n'


def _numpy_installed_as(tmp_path: Path, version: str) -> Path:
    """A folder whose ``numpy-<version>.dist-info`` names ``version`` as the installed numpy."""
    folder = tmp_path / f"site-{version}"
    dist = folder / f"numpy-{version}.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: numpy\nVersion: {version}\n")
    return folder


def _bench(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, site: Path) -> tuple[str, dict[str, object], Path]:
    """`albot1 bench` with ``site`` first on the import path: its output, its one planned cell, that cell's folder."""
    suite = tmp_path / "tiny.toml"
    suite.write_text(SUITE)
    with monkeypatch.context() as patch:
        patch.syspath_prepend(str(site))
        patch.setattr(versions, "_IMPORTED", {})  # a new `albot1 bench` process: nothing read yet
        patch.setattr(versions, "_NOT_IMPORTED", {})
        patch.setattr(limits, "launcher", lambda: "subprocess")
        args = ["bench", str(suite), "--results", str(tmp_path / "results"), "-j", "1", "--no-progress"]
        done = CliRunner().invoke(app, args)
    assert done.exit_code == 0, done.output
    [cell] = json.loads((tmp_path / "results" / "tiny" / "grid.json").read_text())["cells"]
    return done.output, cell, tmp_path / "results" / "tiny" / "runs" / cell["key"]


def test_a_store_made_under_one_numpy_is_run_again_under_another_and_kept_while_unchanged(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _, first, first_dir = _bench(tmp_path, monkeypatch, _numpy_installed_as(tmp_path, "1.0.0"))
    assert json.loads((first_dir / "result.json").read_text())["versions"]["numpy"] == "1.0.0"

    output, second, second_dir = _bench(tmp_path, monkeypatch, _numpy_installed_as(tmp_path, "2.0.0"))
    assert second["key"] != first["key"] and "already complete" not in output  # run again, not kept
    assert json.loads((second_dir / "result.json").read_text())["versions"]["numpy"] == "2.0.0"
    assert (first_dir / "DONE").is_file()  # the older run stays, under its own key, for the older numpy
    for cell, folder in ((first, first_dir), (second, second_dir)):  # each cell process ran what its key names
        assert versions.key_versions(json.loads((folder / "result.json").read_text())["versions"]) == cell["versions"]

    done_at = (second_dir / "DONE").stat().st_mtime_ns
    output, third, _ = _bench(tmp_path, monkeypatch, tmp_path / "site-2.0.0")
    assert third["key"] == second["key"] and "1 of 1 cells already complete (kept)" in output
    assert (second_dir / "DONE").stat().st_mtime_ns == done_at
