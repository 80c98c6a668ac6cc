"""ODOM/TRUEPOS interpolation across a long gap is refused (``max_pose_gap``), not silently invented.

A scan between two ODOM lines 30 s apart used to get the straight-line blend
of the two poses, whatever the robot did in between. The rule
(:data:`albot1.data.loaders.base.DEFAULT_MAX_POSE_GAP_S`, 5 s) sits above the
largest bracketing gap of every registered log read with ``odometry=odom``
(intel 3.11 s).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import DataError, ParseError
from albot1.data.loaders.base import DEFAULT_MAX_POSE_GAP_S
from albot1.data.loaders.carmen.loader import CarmenLoader


def _log(tmp_path: Path, odom_stamps: list[float], scan_stamps: list[float], kind: str = "ODOM") -> Path:
    lines = []
    for stamp, what in sorted([*((s, "o") for s in odom_stamps), *((s, "s") for s in scan_stamps)]):
        if what == "o":
            pose = f"{stamp / 10} 0 0"
            lines.append(f"{kind} {pose} 0 0 0 {stamp:.6f} host {stamp:.6f}")
        else:
            lines.append(f"FLASER 180 {' '.join(['1.0'] * 180)} 0 0 0 0 0 0 {stamp:.6f} host {stamp:.6f}")
    path = tmp_path / "log.clf"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_scan_in_a_long_odom_gap_is_refused_naming_its_line(tmp_path: Path) -> None:
    path = _log(tmp_path, [0.0, 1.0, 31.0, 32.0], [0.5, 10.0, 31.5])
    with pytest.raises(ParseError, match=r"log\.clf:4: scan at t = 10\.000000 s falls in a 30\.000 s gap of the ODOM"):
        CarmenLoader().load(path, odometry="odom").count_scans()


def test_gaps_within_the_limit_interpolate_and_the_option_widens_it(tmp_path: Path) -> None:
    path = _log(tmp_path, [0.0, 1.0, 31.0, 32.0], [0.5, 10.0, 31.5])
    frames = list(CarmenLoader().load(path, odometry="odom", max_pose_gap="inf").frames())
    np.testing.assert_allclose(frames[1].odometry, [1.0, 0.0, 0.0])  # 0.1 + (10 - 1) / 30 * 3.0
    near = _log(tmp_path, [0.0, DEFAULT_MAX_POSE_GAP_S], [1.0])
    assert CarmenLoader().load(near, odometry="odom").count_scans() == 1


def test_truepos_gaps_are_refused_too(tmp_path: Path) -> None:
    path = _log(tmp_path, [0.0, 20.0], [10.0], kind="TRUEPOS")
    with pytest.raises(ParseError, match=r"gap of the TRUEPOS lines"):
        CarmenLoader().load(path, reference="truepos").count_scans()


@pytest.mark.parametrize("value", ["0", "-1", "soon", "nan"])
def test_a_bad_max_pose_gap_is_one_line(tmp_path: Path, value: str) -> None:
    with pytest.raises(DataError, match=rf"log\.clf: max_pose_gap='{value}'; expected seconds > 0"):
        CarmenLoader().load(_log(tmp_path, [0.0, 1.0], [0.5]), max_pose_gap=value)
