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
        # numpy refuses Python's digit grouping, float() takes it: the line must still be named
        ("1 0 0 0 0 0 0 1\n2 0_0.8 0 0 0 0 0 1\n", 2, "value 2 is '0_0.8', expected a number"),
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


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        (
            "dup.tum",
            "0 0 0 0 0 0 0 1\n0.2 1 0 0 0 0 0 1\n# c\n0.2 2 0 0 0 0 0 1\n",
            ":4: lines 2 and 4 both have timestamp 0.2",
        ),
        ("qs.tum", "0 0 0 0 0 0 0.00001 0.00001\n", ":1: quaternion (qx qy qz qw) has length 1.41421e-05"),
        ("qb.tum", "0 0 0 0 0 0 300 400\n", ":1: quaternion (qx qy qz qw) has length 500"),
        ("z.kitti", "0 0 0 0 0 0 0 0 0 0 0 0\n", ":1: the 3x3 part of [R | t] is not a rotation"),
        (
            "s.kitti",
            "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 2 0 0 0 0 1 0\n",
            ":2: the 3x3 part of [R | t] is not a rotation",
        ),
        ("m.kitti", "1 0 0 0 0 -1 0 0 0 0 1 0\n", ":1: the 3x3 part of [R | t] is not a rotation"),
        ("g.kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0_5 0 1 0 0 0 0 1 0\n", ":2: value 4 is '0_5', expected a number"),
        ("big.tum", "0 0 0 0 0 0 0 1\n1 1e308 0 0 0 0 0 1\n", ":2: position (1e+308, 0) m is beyond 1e+08 m"),
        ("ns.tum", "1.7e18 0 0 0 0 0 0 1\n", ":1: timestamp 1.7e+18 is beyond 1e+11; expected seconds"),
    ],
)
def test_absurd_trajectories_are_refused_with_the_line(tmp_path: Path, name: str, text: str, message: str) -> None:
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(DataError) as caught:
        read_trajectory(path)
    assert str(caught.value).startswith(f"{path}{message}")


def test_a_quaternion_close_to_unit_is_normalised(tmp_path: Path) -> None:
    half = np.radians(73.7) / 2
    qz, qw = float(1.005 * np.sin(half)), float(1.005 * np.cos(half))
    (tmp_path / "n.tum").write_text(f"0 1 2 0 0 0 {qz!r} {qw!r}\n")
    _, poses = read_tum(tmp_path / "n.tum")
    assert np.degrees(poses[0, 2]) == pytest.approx(73.7, abs=1e-9)


def test_a_folder_or_a_missing_file_is_named_as_such(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="is a folder; expected a trajectory file"):
        read_trajectory(tmp_path)
    with pytest.raises(DataError, match="trajectory file not found"):
        read_trajectory(tmp_path / "nothing.tum")


def test_a_corrected_carmen_pose_beyond_the_bound_is_refused_with_its_laser_line(tmp_path: Path) -> None:
    path = tmp_path / "c.clf"
    path.write_text(
        "FLASER 3 1.0 2.0 3.0 1.5 -2.25 0.3 1.5 -2.25 0.3 100.25 host 100.25\n"
        "FLASER 3 1.0 2.0 3.0 1e308 -2.25 -3.1 2.5 -2.25 -3.1 100.5 host 100.5\n"
    )
    with pytest.raises(DataError, match=r"c.clf: laser line 1 \(0-based, t = 100.500000 s\): pose \(1e\+308"):
        read_trajectory(path)
