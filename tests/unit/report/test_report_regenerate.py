"""A page's "Regenerate" command names a user's own suite by its path, a shipped suite by its name."""

from __future__ import annotations

from pathlib import Path

from albot1.bench.grid import GridPlan
from albot1.bench.suite import find_suite
from albot1.report.provenance import bench_argument


def _plan(name: str, path: Path | None) -> GridPlan:
    return GridPlan(name, str(path) if path else None, "", [], [], [], {}, [0], ["none"], {"platform": "test"})


def test_a_shipped_suite_is_named_and_an_own_suite_file_is_given_by_path(tmp_path: Path) -> None:
    assert bench_argument(_plan("quick", find_suite("quick").resolve())) == "quick"
    own = tmp_path / "robot.toml"
    own.write_text('[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "x"\n')
    assert bench_argument(_plan("robot", own)) == str(own)  # `albot1 bench robot` would not find it
    shadow = tmp_path / "quick.toml"  # an own file named like a shipped suite is not that suite
    shadow.write_text(own.read_text())
    assert bench_argument(_plan("quick", shadow)) == str(shadow)
    assert bench_argument(_plan("quick", None)) == "quick"
