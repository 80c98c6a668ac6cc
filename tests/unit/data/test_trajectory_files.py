"""Trajectory files of other tools: TUM, KITTI and corrected CARMEN logs, with errors that name file and line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import DataError, ParseError
from albot1.data.trajectory import as_stored, guess_format, read_kitti, read_trajectory, read_tum, write_tum


def test_tum_round_trip_keeps_nanometres_and_the_heading(tmp_path: Path) -> None:
    stamps = np.array([10.0, 10.5, 11.25])
    poses = np.array([[0.0, 0.0, 0.0], [1.123456789, -2.0, 3.0], [-5.5, 4.25, -3.1]])
    write_tum(tmp_path / "t.tum", stamps, poses)
    got_stamps, got = read_tum(tmp_path / "t.tum")
    assert np.array_equal(got_stamps, stamps)
    assert np.abs(got - poses).max() < 2e-9
    assert np.array_equal(as_stored(stamps, poses), got)  # what a run folder stores, without a file


@pytest.mark.parametrize(
    ("text", "line", "problem"),
    [
        ("# t x y z qx qy qz qw\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n", 3, "found 7 values, expected 8"),
        ("1 0 0 0 0 0 0 1\n\n2 0 zero 0 0 0 0 1\n", 3, "value 3 is 'zero', expected a number"),
        ("1 0 0 0 0 0 0 1\n2 nan 0 0 0 0 0 1\n", 2, "value 2 is 'nan', expected a finite number"),
        ("1 0 0 0 0 0 0 1\n# a comment\n2 0 0 0 0 0 0 0\n", 3, "quaternion (qx qy qz qw) has length 0"),
    ],
)
def test_a_bad_tum_line_is_named_with_what_was_expected(tmp_path: Path, text: str, line: int, problem: str) -> None:
    path = tmp_path / "bad.tum"
    path.write_text(text)
    with pytest.raises(ParseError) as caught:
        read_tum(path)
    assert str(caught.value).startswith(f"{path}:{line}: ") and problem in str(caught.value)


def test_kitti_poses_become_planar_poses_and_the_camera_frame_is_refused(tmp_path: Path) -> None:
    yaw = np.radians(30.0)
    c, s = np.cos(yaw), np.sin(yaw)
    (tmp_path / "xy.txt").write_text(f"1 0 0 0 0 1 0 0 0 0 1 0\n{c} {-s} 0 2.5 {s} {c} 0 -1 0 0 1 0\n")
    poses = read_kitti(tmp_path / "xy.txt")
    assert np.allclose(poses, [[0.0, 0.0, 0.0], [2.5, -1.0, yaw]])
    (tmp_path / "xz.txt").write_text("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0.2 0 1 0 0 0 0 1 5.0\n")
    with pytest.raises(ParseError, match="KITTI's camera frame"):
        read_kitti(tmp_path / "xz.txt")


def test_the_format_comes_from_the_name_or_the_first_line(tmp_path: Path) -> None:
    (tmp_path / "a.txt").write_text("# header\n1 0 0 0 0 0 0 1\n")
    (tmp_path / "b.txt").write_text("1 0 0 0 0 1 0 0 0 0 1 0\n")
    (tmp_path / "c.txt").write_text("1 2 3\n")
    assert guess_format(tmp_path / "a.txt") == "tum" and guess_format(tmp_path / "b.txt") == "kitti"
    assert guess_format(Path("run.gfs.log.gz")) == "carmen" and guess_format(Path("x.tum")) == "tum"
    with pytest.raises(DataError, match="cannot tell the trajectory format"):
        guess_format(tmp_path / "c.txt")
    with pytest.raises(DataError, match="trajectory format 'g2o' not known; expected tum | kitti | carmen"):
        read_trajectory(tmp_path / "a.txt", "g2o")
    with pytest.raises(DataError, match="trajectory file not found"):
        read_trajectory(tmp_path / "missing.tum")
