"""Robot, not laser: CARMEN's laser-pose fields are the laser's pose, and ROBOTLASER1's mount is one per log.

CARMEN's robot module writes a laser line's pose fields as the robot's
(odometry) pose composed with the laser's mount (``robot_laser.c``: ``x =
odom_x + offset cos(theta)``, rear laser ``theta = odom_theta + pi``), and its
logger writes ROBOTLASER1 ``laser_pose`` before ``robot_pose``. A reference
read from those fields (``reference=laser-pose``) is the robot's only after the
inverse mount; ROBOTLASER1 lines each restate the mount, and the loader applies
the first line's to every scan, so a later line that disagrees is refused.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.loader import CarmenLoader
from albot1.geometry import se2

ODOMETRY = [(0.0, 0.0, 0.0), (1.0, 0.5, 0.7), (2.0, -1.0, -2.9), (2.5, -1.5, 3.1)]


def _write(tmp_path: Path, lines: list[str]) -> Path:
    path = tmp_path / "log.clf"
    path.write_text("\n".join(lines) + "\n")
    return path


def _fmt(pose: np.ndarray | tuple[float, float, float]) -> str:
    return " ".join(repr(float(v)) for v in pose)


def _old_laser_log(message: str, mount: np.ndarray, corrected: np.ndarray | None = None) -> list[str]:
    """FLASER/RLASER lines as CARMEN writes them: laser pose = odometry * mount, then the odometry."""
    lines = []
    for k, odom in enumerate(ODOMETRY):
        robot = np.array(odom) if corrected is None else corrected[k]
        laser = se2.compose(robot, mount)
        lines.append(f"{message} 181 {' '.join(['2.000'] * 181)} {_fmt(laser)} {_fmt(odom)} {k + 1.0} host {k + 1.0}")
    return lines


def test_flaser_reference_is_the_robot_pose_not_the_laser_pose(tmp_path: Path) -> None:
    """fr079's PARAM robot_frontlaser_offset -0.04: its x y theta fields lie 4 cm behind the odometry fields.
    reference=laser-pose used to return those laser poses as the robot's; now it returns the odometry fields."""
    mount = np.array([-0.04, 0.0, 0.0])
    lines = ["PARAM robot_frontlaser_offset -0.04 0 host 0", *_old_laser_log("FLASER", mount)]
    sequence = CarmenLoader().load(_write(tmp_path, lines), reference="laser-pose")
    assert sequence.metadata.sensor_offset == (-0.04, 0.0, 0.0)
    frames = list(sequence.frames())
    for frame, odom in zip(frames, ODOMETRY, strict=True):
        np.testing.assert_allclose(frame.odometry, odom)  # the odometry fields, unchanged
        np.testing.assert_allclose(frame.reference[:2], odom[:2], atol=1e-12)
        assert abs(se2.wrap(frame.reference[2] - odom[2])) < 1e-12


def test_rlaser_reference_is_not_turned_half_way_round(tmp_path: Path) -> None:
    """An RLASER line's laser pose faces backwards (theta = odom_theta + pi); the robot's reference does not."""
    offset = 0.3
    mount = np.array([-offset, 0.0, math.pi])
    lines = [f"PARAM robot_rearlaser_offset {offset} 0 host 0", *_old_laser_log("RLASER", mount)]
    frames = list(CarmenLoader().load(_write(tmp_path, lines), laser="RLASER", reference="laser-pose").frames())
    for frame, odom in zip(frames, ODOMETRY, strict=True):
        np.testing.assert_allclose(frame.reference[:2], odom[:2], atol=1e-12)
        assert abs(se2.wrap(frame.reference[2] - odom[2])) < 1e-12


def test_corrected_log_reference_and_odometry_segments_move_back_onto_the_robot(tmp_path: Path) -> None:
    """A GMapping-corrected log (both pose fields one corrected pose, laser at the robot's centre for GMapping,
    so that pose is where the scans were taken: the laser's): the reference and the odom-segments chain, which
    starts at that pose, are both the robot's, so the runner puts the scans back exactly where GMapping did."""
    mount = np.array([-0.04, 0.0, 0.0])
    corrected = [(0.0, 0.0, 0.0), (1.1, 0.1, 0.05), (2.0, 0.3, 0.1)]
    lines = ["PARAM robot_frontlaser_offset -0.04 0 host 0", f"ODOM {_fmt((0.0, 0.0, 0.0))} 0 0 0 0.0 host 0.0"]
    for k, pose in enumerate(corrected):
        lines.append(f"FLASER 180 {' '.join(['1.000'] * 180)} {_fmt(pose)} {_fmt(pose)} {k}.0 host {k}.0")
        lines.append(f"ODOM {_fmt(pose)} 0 0 0 0.0 host 0.0")
        step = se2.compose(np.array(pose), np.array([1.0, 0.0, 0.0]))
        lines.append(f"ODOM {_fmt(step)} 0 0 0 {k + 1}.0 host {k + 1}.0")
    sequence = CarmenLoader().load(_write(tmp_path, lines), odometry="odom-segments", reference="laser-pose")
    frames = list(sequence.frames())
    for frame, pose in zip(frames, corrected, strict=True):
        np.testing.assert_allclose(se2.compose(frame.reference, mount), pose, atol=1e-12)
    chain = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])  # in the laser's frame, as logged
    np.testing.assert_allclose(se2.compose(np.array([f.odometry for f in frames]), mount), chain, atol=1e-12)


def test_corrected_log_perfect_odometry_is_the_reference_to_the_bit(tmp_path: Path) -> None:
    """``odometry=laser-pose`` on a corrected log (both field sets one corrected pose) is the generalisation
    suite's perfect odometry: it must be read as the reference is (moved onto the robot), not one mount away."""
    mount = np.array([-0.04, 0.0, 0.0])
    corrected = [(0.0, 0.0, 0.0), (1.1, 0.1, 0.05), (2.0, 0.3, 1.6), (2.1, 1.3, -3.0)]
    lines = ["PARAM robot_frontlaser_offset -0.04 0 host 0"]
    for k, pose in enumerate(corrected):
        lines.append(f"FLASER 180 {' '.join(['1.000'] * 180)} {_fmt(pose)} {_fmt(pose)} {k}.0 host {k}.0")
    sequence = CarmenLoader().load(_write(tmp_path, lines), odometry="laser-pose", reference="laser-pose")
    frames = list(sequence.frames())
    for frame, pose in zip(frames, corrected, strict=True):
        np.testing.assert_array_equal(frame.odometry, frame.reference)
        np.testing.assert_allclose(se2.compose(frame.odometry, mount), pose, atol=1e-12)


def test_raw_log_odometry_fields_stay_the_robot_odometry(tmp_path: Path) -> None:
    """On a raw log the two field sets differ by the mount: the odometry fields are the robot's, taken as logged."""
    mount = np.array([-0.04, 0.0, 0.0])
    lines = ["PARAM robot_frontlaser_offset -0.04 0 host 0", *_old_laser_log("FLASER", mount)]
    frames = list(CarmenLoader().load(_write(tmp_path, lines), odometry="laser-pose").frames())
    for frame, odom in zip(frames, ODOMETRY, strict=True):
        np.testing.assert_array_equal(frame.odometry, np.array(odom))


def _robotlaser(robot: tuple[float, float, float], mount: tuple[float, float, float], stamp: float) -> str:
    laser = se2.compose(np.array(robot), np.array(mount))
    return (
        f"ROBOTLASER1 0 -1.0 1.0 0.5 30.0 0.01 0 3 1.000 2.000 3.000 0 {_fmt(laser)} {_fmt(robot)} "
        f"0 0 0 0 0 {stamp} host {stamp}"
    )


def test_robotlaser1_reference_is_the_laser_pose_fields_moved_onto_the_robot(tmp_path: Path) -> None:
    """reference=laser-pose reads a ROBOTLASER1 line's laser_pose fields composed with the inverse mount. On any
    log the loader accepts (one mount for every line) that equals the robot_pose fields, so this pins the reading
    down rather than guarding an old defect: a vasco-corrected log (laser_pose corrected apart from robot_pose),
    where the two differ, is refused by the one-mount check without PARAM lines, and read with the PARAM mount
    (the tests below)."""
    mount = (0.22, 0.0, 0.0)
    path = _write(tmp_path, [_robotlaser(odom, mount, k + 1.0) for k, odom in enumerate(ODOMETRY)])
    frames = list(CarmenLoader().load(path, reference="laser-pose").frames())
    for frame, odom in zip(frames, ODOMETRY, strict=True):
        np.testing.assert_allclose(frame.reference[:2], odom[:2], atol=1e-12)
        assert abs(se2.wrap(frame.reference[2] - odom[2])) < 1e-12


def test_robotlaser1_line_with_another_mount_is_refused(tmp_path: Path) -> None:
    """The mount was read from the first line only; a later line's laser elsewhere on the robot was ignored."""
    lines = [_robotlaser(odom, (0.22, 0.0, 0.0), k + 1.0) for k, odom in enumerate(ODOMETRY)]
    lines[2] = _robotlaser(ODOMETRY[2], (0.30, 0.0, 0.0), 3.0)
    with pytest.raises(ParseError, match=r"log\.clf:3: ROBOTLASER1 .*\(0\.3, .*\).*first ROBOTLASER1 line .*\(0\.22, "):
        CarmenLoader().load(_write(tmp_path, lines)).count_scans()


def test_robotlaser1_log_corrected_by_vasco_reads_with_the_param_mount(tmp_path: Path) -> None:
    """vasco corrects each line's laser pose and leaves the robot pose as the odometry, so the lines' own mounts
    differ. With the mount stated by PARAM (what the robot module composed the laser poses with) such a log is
    read: the odometry is the robot pose fields, the reference the corrected laser poses moved onto the robot.
    Without the PARAM lines it is refused (test above): nothing else tells a corrected line from another laser's."""
    mount = np.array([0.22, 0.0, 0.0])
    corrected = [(0.0, 0.0, 0.0), (1.05, 0.45, 0.72), (2.1, -0.9, -2.85), (2.4, -1.6, 3.12)]
    lines = [
        f"PARAM robot_frontlaser_offset {mount[0]} host 0",
        *(
            f"ROBOTLASER1 0 -1.0 1.0 0.5 30.0 0.01 0 3 1.000 2.000 3.000 0 {_fmt(se2.compose(np.array(fixed), mount))} "
            f"{_fmt(odom)} 0 0 0 0 0 {k + 1.0} host {k + 1.0}"
            for k, (odom, fixed) in enumerate(zip(ODOMETRY, corrected, strict=True))
        ),
    ]
    sequence = CarmenLoader().load(_write(tmp_path, lines), reference="laser-pose")
    assert sequence.metadata.sensor_offset == (0.22, 0.0, 0.0)
    frames = list(sequence.frames())
    for frame, odom, fixed in zip(frames, ODOMETRY, corrected, strict=True):
        np.testing.assert_array_equal(frame.odometry, np.array(odom))
        np.testing.assert_allclose(frame.reference[:2], fixed[:2], atol=1e-12)
        assert abs(se2.wrap(frame.reference[2] - fixed[2])) < 1e-12


def test_robotlaser1_mount_printed_with_six_decimals_is_accepted(tmp_path: Path) -> None:
    """CARMEN prints poses with %f (6 decimals): fr-clinic's per-line mounts scatter by 1.3e-6 m."""
    lines = []
    for k, odom in enumerate(ODOMETRY):
        laser = se2.compose(np.array(odom), np.array([0.22, 0.0, 0.0]))
        fields = " ".join(f"{v:.6f}" for v in (*laser, *odom))
        lines.append(f"ROBOTLASER1 0 -1.0 1.0 0.5 30.0 0.01 0 3 1.0 2.0 3.0 0 {fields} 0 0 0 0 0 {k}.5 host {k}.5")
    assert CarmenLoader().load(_write(tmp_path, lines)).count_scans() == len(ODOMETRY)


def test_a_corrected_carmen_trajectory_file_reads_as_robot_poses(tmp_path: Path) -> None:
    """``albot1 evaluate --trajectory run.clf`` (GMapping's output) is scored against robot poses: its laser-pose
    fields are read through the loader's reference, so they come back moved onto the robot as well."""
    from albot1.data.trajectory import read_carmen_poses

    mount = np.array([-0.04, 0.0, 0.0])
    lines = ["PARAM robot_frontlaser_offset -0.04 0 host 0", *_old_laser_log("FLASER", mount)]
    _, poses = read_carmen_poses(_write(tmp_path, lines))
    np.testing.assert_allclose(poses[:, :2], np.array(ODOMETRY)[:, :2], atol=1e-12)
