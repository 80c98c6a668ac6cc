"""CARMEN log variants a researcher brings: the rear ROBOTLASER2 laser, laser kinds the loader does not read,
and a laser-mount PARAM that changes part way through the log.

CARMEN's playback (``playback.c``, ``logger_callbacks``) defines ROBOTLASER2 (the rear laser, laid out as
ROBOTLASER1) and LASER3..5, RAWLASER5, ROBOTLASER3..5 beside the messages this loader reads.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.loader import CarmenLoader
from albot1.data.loaders.registry import load
from albot1.geometry import se2

ROBOT = [(0.0, 0.0, 0.0), (0.5, 0.1, 0.3), (1.0, 0.4, -2.8)]
#: CARMEN's rear laser 0.2 m behind the centre, looking backwards (``robot_laser.c``: theta = odom_theta + pi)
REAR_MOUNT = np.array([-0.2, 0.0, math.pi])


def _fmt(pose: np.ndarray | tuple[float, float, float]) -> str:
    return " ".join(repr(float(v)) for v in pose)


def _robotlaser(
    message: str, robot: tuple[float, float, float], mount: np.ndarray, ranges: list[float], t: float
) -> str:
    n, step = len(ranges), math.radians(45.0)
    laser = se2.compose(np.array(robot), mount)
    head = f"{message} 0 {-math.pi / 2!r} {step * (n - 1)!r} {step!r} 30.0 0.01 0 {n} "
    return head + " ".join(map(str, ranges)) + f" 0 {_fmt(laser)} {_fmt(robot)} 0 0 0.5 0.5 0 {t} host {t}"


def _write(tmp_path: Path, lines: list[str], name: str = "log.clf") -> Path:
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_rear_robotlaser2_log_is_recognised_and_read_with_its_backward_mount(tmp_path: Path) -> None:
    """A log of ROBOTLASER2 lines only used to be 'no known format'; now laser=ROBOTLASER2 reads it: ranges and
    angles as logged, the robot pose as odometry, the mount from the lines (0.2 m behind, facing backwards)."""
    ranges = [1.0, 2.0, 30.0, 0.0, 4.5]
    path = _write(tmp_path, [_robotlaser("ROBOTLASER2", r, REAR_MOUNT, ranges, 1.0 + k) for k, r in enumerate(ROBOT)])
    with pytest.raises(ParseError, match=r"log.clf:1: no front-laser scans.*3 ROBOTLASER2 lines.*laser=ROBOTLASER2"):
        load(str(path))
    seq = load(str(path), laser="ROBOTLASER2")
    frames = list(seq.frames())
    assert len(frames) == 3
    x, y, yaw = seq.metadata.sensor_offset
    assert (x, y) == pytest.approx((-0.2, 0.0), abs=1e-12) and abs(math.remainder(yaw - math.pi, 2 * math.pi)) < 1e-12
    for frame, robot in zip(frames, ROBOT, strict=True):
        np.testing.assert_allclose(frame.odometry, robot, atol=1e-12)
        np.testing.assert_allclose(frame.scan.angles, -math.pi / 2 + math.radians(45.0) * np.arange(5), atol=1e-12)
        np.testing.assert_array_equal(frame.scan.ranges, [1.0, 2.0, np.nan, np.nan, 4.5])  # 30 = max, 0 = none
    reference = list(load(str(path), laser="ROBOTLASER2", reference="laser-pose").frames())
    for frame, robot in zip(reference, ROBOT, strict=True):
        assert frame.reference is not None
        np.testing.assert_allclose(frame.reference[:2], robot[:2], atol=1e-9)  # the laser pose, unmounted


def test_a_robotlaser2_line_whose_mount_differs_is_refused_naming_robotlaser2(tmp_path: Path) -> None:
    lines = [_robotlaser("ROBOTLASER2", r, REAR_MOUNT, [2.0] * 5, 1.0 + k) for k, r in enumerate(ROBOT)]
    lines[2] = _robotlaser("ROBOTLASER2", ROBOT[2], np.array([0.3, 0.0, 0.0]), [2.0] * 5, 3.0)
    with pytest.raises(ParseError, match=r"log.clf:3: ROBOTLASER2 laser pose vs robot pose .*first ROBOTLASER2 line"):
        list(load(str(_write(tmp_path, lines)), laser="ROBOTLASER2").frames())


def test_laser_lines_the_loader_does_not_read_are_named_when_no_laser_is_readable(tmp_path: Path) -> None:
    """LASER3 (the old form of RAWLASER3) used to give only 'expected FLASER, ROBOTLASER1 or RAWLASER1 lines'."""
    lines = [f"LASER3 3 2.0 2.0 2.0 {1.0 + k} host {1.0 + k}" for k in range(2)]
    path = _write(tmp_path, lines)
    assert CarmenLoader().sniff(path)
    with pytest.raises(ParseError, match=r"log.clf:1: no front-laser.* 2 LASER3 lines, a laser this loader does not"):
        load(str(path))


def _flaser(k: int) -> str:
    return f"FLASER 3 2.0 2.0 2.0 {0.1 * k} 0 0 {0.1 * k} 0 0 {1.0 + k} host {1.0 + k}"


def test_a_mount_param_that_changes_mid_log_is_refused_at_its_line(tmp_path: Path) -> None:
    """Two recordings joined: PARAM robot_frontlaser_offset 0.1, two scans, then 0.4. Every scan used to be placed
    with the last value (0.4), the first two 30 cm off, without a word."""
    lines = ["PARAM robot_frontlaser_offset 0.1 0 host 0", _flaser(0), _flaser(1)]
    lines += ["PARAM robot_frontlaser_offset 0.4 0 host 0", _flaser(2), _flaser(3)]
    path = _write(tmp_path, lines)
    with pytest.raises(ParseError, match=r"log.clf:4: PARAM robot_frontlaser_offset changes from 0.1 to 0.4; expe"):
        list(load(str(path)).frames())


def test_a_repeated_mount_param_and_the_other_lasers_mount_param_are_no_change(tmp_path: Path) -> None:
    lines = ["PARAM robot_frontlaser_offset 0.1 0 host 0", _flaser(0), "PARAM robot_frontlaser_offset 0.10 0 host 0"]
    lines += ["PARAM robot_rearlaser_offset -0.3 0 host 0", _flaser(1), "PARAM robot_rearlaser_offset -0.2 0 host 0"]
    seq = load(str(_write(tmp_path, [*lines, _flaser(2)])))
    assert len(list(seq.frames())) == 3 and seq.metadata.sensor_offset == (0.1, 0.0, 0.0)


def test_a_mount_param_restated_before_the_first_scan_takes_its_last_value(tmp_path: Path) -> None:
    """belgioioso-corrected's PARAM block states robot_frontlaser_offset 0.0 (line 3), then -0.04 (line 17), all
    before its first FLASER line: the last value is the mount, as before, and nothing is refused."""
    lines = ["PARAM robot_frontlaser_offset 0.0 nohost 0", "PARAM robot_frontlaser_offset -0.04 nohost 0"]
    seq = load(str(_write(tmp_path, [*lines, _flaser(0), _flaser(1)])))
    assert len(list(seq.frames())) == 2 and seq.metadata.sensor_offset == (-0.04, 0.0, 0.0)


def test_a_mount_param_first_stated_after_the_logs_head_is_refused_as_a_change(tmp_path: Path) -> None:
    """The loader takes the mount from the log's head (the PARAMs up to the chunk of the first scan); a
    robot_frontlaser_offset first stated past it used to be taken silently: every scan placed at (0, 0, 0), while
    the log says 0.3 from there on. The same lines in a short log give the mount 0.3; past the head it is refused."""
    before = [_flaser(k) for k in range(40_000)]  # 2.8 MB: past the 256 KiB head and the first 2 MiB chunk
    path = _write(tmp_path, [*before, "PARAM robot_frontlaser_offset 0.3 0 host 0", _flaser(40_000)])
    expected = r"log.clf:40001: PARAM robot_frontlaser_offset changes \(not stated before it: 0\) to 0.3; expected"
    with pytest.raises(ParseError, match=expected):
        list(load(str(path)).frames())
    short = load(str(_write(tmp_path, [_flaser(0), "PARAM robot_frontlaser_offset 0.3 0 host 0", _flaser(1)], "s.clf")))
    assert len(list(short.frames())) == 2 and short.metadata.sensor_offset == (0.3, 0.0, 0.0)
