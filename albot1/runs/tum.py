"""TUM trajectory files (``t x y z qx qy qz qw``) for planar poses.

Written with z = 0 and a yaw-only quaternion, 9 decimals, so that evo and
other tools read them directly.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.runs.errors import RunError


def write_tum(path: Path, timestamps: NDArray[np.float64], poses: NDArray[np.float64]) -> None:
    half = poses[:, 2] / 2.0
    rows = np.column_stack([timestamps, poses[:, 0], poses[:, 1], np.zeros(len(poses)),
                            np.zeros(len(poses)), np.zeros(len(poses)), np.sin(half), np.cos(half)])
    np.savetxt(path, rows, fmt="%.9f", header="timestamp x y z qx qy qz qw", comments="# ")


def read_tum(path: Path) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(timestamps, poses)``; the heading is the yaw of the quaternion."""
    try:
        rows = np.loadtxt(path, ndmin=2, comments="#")
    except (OSError, ValueError) as exc:
        raise RunError(f"{path}: not a TUM trajectory (t x y z qx qy qz qw per line): {exc}") from None
    if rows.shape[1] != 8:
        raise RunError(f"{path}: expected 8 columns (t x y z qx qy qz qw), found {rows.shape[1]}")
    qx, qy, qz, qw = rows[:, 4], rows[:, 5], rows[:, 6], rows[:, 7]
    yaw = np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return rows[:, 0], np.column_stack([rows[:, 1], rows[:, 2], yaw])
