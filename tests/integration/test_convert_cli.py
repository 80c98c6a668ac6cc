"""``albot1 convert`` as a user runs it: output, format guessing, one-line errors with exit 1."""

from __future__ import annotations

import itertools
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from albot1.cli.app import main
from albot1.data.loaders.registry import load

pytestmark = pytest.mark.integration


def run_cli(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    monkeypatch.setattr(sys, "argv", ["albot1", *args])
    try:
        main()
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def test_convert_chain_carmen_to_bag_to_albot_log(
    data_file: Callable[[str], Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    aces = data_file("radish/aces.clf.bz2")
    code, out, err = run_cli(monkeypatch, capsys, "convert", str(aces), str(tmp_path / "a.bag"), "--limit", "40")
    assert code == 0, err
    assert out.strip() == f"wrote 40 scans from {aces} to {tmp_path / 'a.bag'} (ros1)"
    code, out, err = run_cli(
        monkeypatch,
        capsys,
        "convert",
        str(tmp_path / "a.bag"),
        str(tmp_path / "a.out"),
        "--format",
        "albot-log",
        "--scan-topic",
        "/scan",
    )
    assert code == 0, err
    assert "(albot-log)" in out
    first = [f.scan.ranges for f in itertools.islice(load(aces).frames(), 40)]
    again = [f.scan.ranges for f in load(tmp_path / "a.out").frames()]
    assert len(again) == 40
    assert all(np.array_equal(a.astype(np.float32), b.astype(np.float32), equal_nan=True) for a, b in zip(first, again))


def test_convert_errors_are_one_line(
    data_file: Callable[[str], Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    aces = str(data_file("radish/aces.clf.bz2"))
    code, _, err = run_cli(monkeypatch, capsys, "convert", aces, str(tmp_path / "out.xyz"), "--limit", "5")
    assert code == 1 and err.count("\n") == 1
    assert err.startswith("albot1: error: ") and "cannot tell the output format" in err and ".bag (ros1)" in err

    bad = str(data_file("bad-inputs/old-rosbag-laser_scan_matcher-demo.bag"))
    code, _, err = run_cli(monkeypatch, capsys, "convert", bad, str(tmp_path / "x.albotlog"))
    assert code == 1 and err.count("\n") == 1 and bad in err and "damaged ROS1 bag: the index data record" in err
    assert not (tmp_path / "x.albotlog").exists()

    assert run_cli(monkeypatch, capsys, "convert", aces, str(tmp_path / "b.bag"), "--limit", "3")[0] == 0
    code, _, err = run_cli(
        monkeypatch,
        capsys,
        "convert",
        str(tmp_path / "b.bag"),
        str(tmp_path / "c.albotlog"),
        "--scan-topic",
        "/base_scan",
    )
    assert code == 1 and "'/base_scan' (scan_topic / --scan-topic) is not in the bag" in err
    assert "/scan (sensor_msgs/msg/LaserScan, 3 msgs)" in err and "/odom (nav_msgs/msg/Odometry, 3 msgs)" in err

    code, _, err = run_cli(monkeypatch, capsys, "convert", aces, str(tmp_path / "b.bag"), "--limit", "3")
    assert code == 1 and "exists already" in err
