"""An external method's ``{dataset}`` file is scored against one log only.

``d1/run.clf`` and ``d2/run.clf`` both give ``{dataset}`` = ``run``: the file made on one used to be scored
against the other too, without a word, wherever their times overlapped (here d2 is d1's first half, so every
pose of the file matched a scan of d2).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.bench.errors import SuiteError
from albot1.bench.plan import plan_suite
from albot1.bench.suite import load_suite
from albot1.settings import get_settings

RANGES = " ".join(["2.0"] * 180)


def log(path: Path, scans: int) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = [f"FLASER 180 {RANGES} {0.1 * i} 0 0 {0.1 * i} 0 0 {1.0 + i} nohost {1.0 + i}" for i in range(scans)]
    path.write_text("\n".join(lines) + "\n")


def suite(tmp_path: Path, *datasets: str) -> Path:
    (tmp_path / "mine").mkdir(exist_ok=True)
    (tmp_path / "mine" / "run.tum").write_text("".join(f"{1.0 + i} {0.1 * i} 0 0 0 0 0 1\n" for i in range(12)))
    path = tmp_path / "s.toml"
    entries = "".join(f'\n[[datasets]]\nname = "{d}"\n' for d in datasets)
    path.write_text(f'[[methods]]\nname = "mine"\ntrajectories = "mine/{{dataset}}.tum"\n{entries}')
    return path


def test_two_logs_of_one_file_name_are_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    log(tmp_path / "d1" / "run.clf", 12)
    log(tmp_path / "d2" / "run.clf", 6)
    with pytest.raises(
        SuiteError,
        match=r"method 'mine \(external\)': datasets 'd1/run.clf' and 'd2/run.clf' are two logs \(.*d1/run\.clf, "
        r".*d2/run\.clf\) but trajectories = 'mine/\{dataset\}\.tum' gives both the file .*mine/run\.tum; expected "
        r"one file per log",
    ):
        plan_suite(load_suite(suite(tmp_path, "d1/run.clf", "d2/run.clf")), get_settings())


def test_slices_and_options_of_one_log_share_its_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    log(tmp_path / "d1" / "run.clf", 12)
    plan = plan_suite(
        load_suite(suite(tmp_path, "d1/run.clf", "d1/run.clf[:6]", "./d1/run.clf?max_range=50")), get_settings()
    )
    files = {c.trajectory for c in plan.cells}
    assert len(plan.cells) == 3 and files == {str(tmp_path / "mine" / "run.tum")}
