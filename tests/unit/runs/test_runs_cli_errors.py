"""`albot1 run` and `albot1 evaluate` on bad input: one line on stderr, exit 1, nothing run or written first."""

from __future__ import annotations

import errno
import json
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from albot1.cli import app as app_module

WORLD = "synthetic-corridor"


def albot1(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    """Run the console entry point in-process: (exit code, stdout, stderr)."""
    monkeypatch.setattr(sys, "argv", ["albot1", *args])
    with pytest.raises(SystemExit) as ended:
        app_module.main()
    out = capsys.readouterr()
    code = ended.value.code
    return (code if isinstance(code, int) else 0), out.out, out.err


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("albot1: error: ") and "Traceback" not in err, err
    return lines[0]


def test_the_scan_limit_is_part_of_the_runs_name_and_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    folders = []
    for limit in ("20", "30", "20"):
        code, out, _ = albot1(monkeypatch, capsys, "run", "odometry", WORLD, "--limit", limit, "--out", str(tmp_path))
        assert code == 0
        folders.append(out.strip().rsplit(" -> ", 1)[1])
    assert folders[0] != folders[1] and folders[0] == folders[2]  # same prefix, same folder; other prefix, other
    for folder, scans in zip(folders, (20, 30, 20)):
        result = json.loads((Path(folder) / "result.json").read_text())
        assert result["dataset"] == f"{WORLD}[:{scans}]" and result["scans"] == scans
    code, out, _ = albot1(monkeypatch, capsys, "run", "odometry", f"{WORLD}[:30]", "--out", str(tmp_path))
    assert code == 0 and out.strip().endswith(folders[1])  # --limit 30 and NAME[:30] are the same run


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--limit", "0"], "--limit 0: expected a positive number of scans (at least 1)"),
        (["--limit", "-5"], "--limit -5: expected a positive number of scans"),
        (["--seed", "-1"], "seed -1: expected an integer from 0 to 9223372036854775807"),
        (["--seed", str(2**64)], f"seed {2**64}: expected an integer from 0"),
        (
            ["--degrade", "gauss:1"],
            "degradation 'gauss:1': gauss takes 2 value(s) (gauss:SIGMA_XY_M:SIGMA_THETA_DEG), got 1",
        ),
    ],
)
def test_bad_arguments_are_one_line_before_anything_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], args: list[str], words: str
) -> None:
    code, _, err = albot1(monkeypatch, capsys, "run", "odometry", WORLD, "--out", str(tmp_path / "runs"), *args)
    assert code == 1 and words in one_line(err)
    assert not (tmp_path / "runs").exists() or not any((tmp_path / "runs").iterdir())


def test_an_out_folder_that_cannot_hold_runs_is_refused_before_the_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "file").write_text("x")
    for out, words in (
        (tmp_path / "file", "is a file, not a folder"),
        (tmp_path / "file" / "runs", f"cannot be made: {tmp_path / 'file'} is a file"),
    ):
        code, _, err = albot1(monkeypatch, capsys, "run", "odometry", WORLD, "--out", str(out))
        assert code == 1 and f"--out {out}: {words}" in one_line(err)


def test_an_os_error_that_reaches_the_entry_point_is_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def full() -> None:
        raise OSError(errno.ENOSPC, "No space left on device", "runs/abc/trajectory.tum")

    monkeypatch.setattr(app_module, "app", full)
    code, _, err = albot1(monkeypatch, capsys)
    assert code == 1
    assert one_line(err) == "albot1: error: runs/abc/trajectory.tum: cannot read or write it: no space left on device"


def test_evaluate_on_a_damaged_run_folder_is_one_line_naming_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = albot1(monkeypatch, capsys, "run", "odometry", WORLD, "--limit", "20", "--out", str(tmp_path))
    assert code == 0
    run_dir = Path(out.strip().rsplit(" -> ", 1)[1])
    for damage, words in (
        (lambda: (run_dir / "per_scan_ns.npy").unlink(), "per_scan_ns.npy: missing from a run folder marked complete"),
        (lambda: np.save(run_dir / "per_scan_ns.npy", np.zeros(2)), "per_scan_ns.npy: holds float64 of shape (2,)"),
        (lambda: (run_dir / "result.json").write_text('{"method": '), "result.json: cannot read a ResultRecord"),
    ):
        damage()
        code, _, err = albot1(monkeypatch, capsys, "evaluate", str(run_dir))
        assert code == 1 and words in one_line(err)


def _keep_lines(file: Path, keep: slice) -> None:
    lines = file.read_text(encoding="utf-8").splitlines(keepends=True)
    file.write_text(lines[0] + "".join(lines[1:][keep]), encoding="utf-8")  # the header kept, poses sliced


def _shift_stamp(file: Path, pose: int) -> None:
    lines = file.read_text(encoding="utf-8").splitlines(keepends=True)
    fields = lines[pose].split(" ")
    fields[0] = f"{float(fields[0]) + 0.5:.9f}"
    lines[pose] = " ".join(fields)
    file.write_text("".join(lines), encoding="utf-8")


@pytest.mark.parametrize(
    ("name", "damage", "words"),
    [
        # a copy cut short at a line boundary parses as a valid shorter trajectory
        ("trajectory.tum", lambda f: _keep_lines(f, slice(0, 12)), "trajectory.tum: 12 poses, expected 20"),
        ("odometry.tum", lambda f: _keep_lines(f, slice(0, 19)), "odometry.tum: 19 poses, expected 20"),
        ("reference.tum", lambda f: _keep_lines(f, slice(3, None)), "reference.tum: 17 poses, expected 20"),
        ("odometry.tum", lambda f: _shift_stamp(f, 5), "odometry.tum: pose 5 has stamp"),
    ],
)
def test_evaluate_refuses_a_run_file_that_lost_or_moved_scans(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    name: str,
    damage: Callable[[Path], None],
    words: str,
) -> None:
    """Scored as found, a truncated trajectory made every metric "does not apply" with exit 0: damage, not a result."""
    code, out, _ = albot1(monkeypatch, capsys, "run", "odometry", WORLD, "--limit", "20", "--out", str(tmp_path))
    assert code == 0
    run_dir = Path(out.strip().rsplit(" -> ", 1)[1])
    damage(run_dir / name)
    code, _, err = albot1(monkeypatch, capsys, "evaluate", str(run_dir))
    line = one_line(err)
    assert code == 1 and words in line and "damaged or edited by hand" in line, line
