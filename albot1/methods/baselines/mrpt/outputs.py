"""Read what MRPT's ``icp-slam`` and ``rbpf-slam`` leave in their output folder.

Every reader checks the shape of what it reads and raises
:class:`BaselineError` naming ``file:line`` and what was expected: MRPT
exits with status 0 after many failures, so its files are the only
evidence of success.

Files (MRPT 2.5):

* ``icp-slam/log_estimated_path.txt``: ``step x y yaw`` (m, m, rad), one line
  per rawlog object; with the observations layout step ``2k`` is scan
  ``k``'s odometry and step ``2k + 1`` the scan itself, in the odometry frame.
* ``icp-slam/_finalmaps_.txt_mrpt__maps__CSimplePointsMap_00.txt``: the point
  map, ``x y z``.
* ``*/log_times.txt``: MRPT's own time per step: ``ms map_size`` (icp-slam);
  ``step ms map_size inserted`` after two ``%`` header lines (rbpf-slam).
* ``rbpf-slam/most_likely_path.txt``: ``x y yaw`` (3 decimals) of the most
  likely particle's path, one pose per filter update plus the initial pose.
* ``rbpf-slam/log_estimated_path.txt``: ``step x y z yaw pitch roll t`` of the
  particle mean at every scan.
* ``rbpf-slam/finalMap_mrpt__maps__COccupancyGridMap2D_00.png`` and
  ``..._limits.txt`` (``x_min x_max y_min y_max``): the most likely grid, row 0
  at ``y_max``, grey level = probability of the cell being free.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.errors import BaselineError

ICP_POINT_MAP = "_finalmaps_.txt_mrpt__maps__CSimplePointsMap_00.txt"
GRID_IMAGE = "finalMap_mrpt__maps__COccupancyGridMap2D_00.png"
GRID_LIMITS = "finalMap_mrpt__maps__COccupancyGridMap2D_00_limits.txt"

_TOTAL_TIME = re.compile(r"\*\*END\*\* \(total time: ([0-9.eE+-]+) sec\)")


def read_rows(path: Path, columns: int, what: str) -> FloatArray:
    """Numeric rows of a whitespace-separated text file (``%`` lines are comments), shape ``(n, columns)``."""
    if not path.is_file():
        raise BaselineError(f"{path}: missing; MRPT did not write its {what}")
    rows: list[list[float]] = []
    with path.open("r", encoding="ascii", errors="replace") as handle:
        for number, line in enumerate(handle, start=1):
            text = line.strip()
            if not text or text.startswith("%"):
                continue
            parts = text.split()
            if len(parts) != columns:
                raise BaselineError(
                    f"{path}:{number}: {len(parts)} fields; expected {columns} in MRPT's {what} ({text[:60]!r})"
                )
            try:
                values = [float(p) for p in parts]
            except ValueError:
                raise BaselineError(f"{path}:{number}: non-numeric field in MRPT's {what} ({text[:60]!r})") from None
            rows.append(values)
    return np.asarray(rows, dtype=float).reshape(-1, columns)


def total_time_s(stdout_text: str) -> float | None:
    """MRPT's own "total time" of the mapping loop, from the application's log (None if absent)."""
    found = _TOTAL_TIME.findall(stdout_text)
    return float(found[-1]) if found else None


def last_error_line(text: str) -> str:
    """The most telling line of a failed MRPT run's output: its exception message, else the last line."""
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    for i, line in enumerate(lines):
        if line.startswith("Message:"):
            return line
        if "==== MRPT exception ====" in line and i + 1 < len(lines):
            return lines[i + 1]
    return lines[-1] if lines else "(no output)"


# -- icp-slam ------------------------------------------------------------------------------------------------


def icp_poses(out_dir: Path, scans: int) -> FloatArray:
    """One pose per scan from icp-slam's estimated path (observations layout: every second step)."""
    path = out_dir / "log_estimated_path.txt"
    rows = read_rows(path, 4, "estimated path")
    if len(rows) != 2 * scans:
        raise BaselineError(
            f"{path}: {len(rows)} steps; expected {2 * scans} (an odometry and a scan step for each of {scans} "
            f"scans): icp-slam stopped early or read the rawlog differently"
        )
    if not np.array_equal(rows[:, 0], np.arange(2 * scans)):
        raise BaselineError(f"{path}: steps are not numbered 0..{2 * scans - 1}")
    return rows[1::2, 1:4].copy()


def icp_point_map(out_dir: Path) -> FloatArray:
    """The final point map ``(K, 2)`` (x, y) in icp-slam's odometry frame."""
    return read_rows(out_dir / ICP_POINT_MAP, 3, "point map")[:, :2].copy()


def icp_steps(out_dir: Path, steps: int) -> tuple[FloatArray, FloatArray]:
    """MRPT's time per step (ms) and the map size (scans inserted so far), one row per rawlog object."""
    path = out_dir / "log_times.txt"
    rows = read_rows(path, 2, "step times")
    if len(rows) != steps:
        raise BaselineError(f"{path}: {len(rows)} steps; expected {steps}")
    return rows[:, 0].copy(), rows[:, 1].copy()


# -- rbpf-slam -----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RbpfSteps:
    """rbpf-slam's per-scan log: time (ms) and whether the filter ran and the scan entered the maps."""

    time_ms: FloatArray
    updated: NDArray[np.bool_]


def rbpf_steps(out_dir: Path, scans: int) -> RbpfSteps:
    """``log_times.txt`` of rbpf-slam: one row per scan, numbered from 0."""
    path = out_dir / "log_times.txt"
    rows = read_rows(path, 4, "step times")
    if len(rows) != scans:
        raise BaselineError(f"{path}: {len(rows)} steps; expected {scans} (one per scan): rbpf-slam stopped early")
    if not np.array_equal(rows[:, 0], np.arange(scans)):
        raise BaselineError(f"{path}: steps are not numbered 0..{scans - 1}")
    flags = rows[:, 3]
    if not np.isin(flags, (0.0, 1.0)).all():
        raise BaselineError(f"{path}: the 'inserted' column holds values other than 0 and 1")
    updated = flags.astype(bool)
    if scans and not updated[0]:
        raise BaselineError(f"{path}: the first scan was not inserted; rbpf-slam always inserts it")
    return RbpfSteps(time_ms=rows[:, 1].copy(), updated=updated)


def rbpf_mean_poses(out_dir: Path, scans: int) -> FloatArray:
    """The particle mean at every scan (x, y, yaw), relative to the first scan's pose."""
    path = out_dir / "log_estimated_path.txt"
    rows = read_rows(path, 8, "estimated path")
    if len(rows) != scans:
        raise BaselineError(f"{path}: {len(rows)} poses; expected {scans} (one per scan)")
    return rows[:, [1, 2, 4]].copy()


def rbpf_best_path(out_dir: Path, updates: int) -> FloatArray:
    """The most likely particle's path: the initial pose and one pose per filter update, ``(updates + 1, 3)``."""
    path = out_dir / "most_likely_path.txt"
    rows = read_rows(path, 3, "most likely path")
    if len(rows) != updates + 1:
        raise BaselineError(
            f"{path}: {len(rows)} poses; expected {updates + 1} (the initial pose and one per filter update "
            f"logged in log_times.txt)"
        )
    return rows


def poses_between_updates(best_path: FloatArray, updated: NDArray[np.bool_], odometry: FloatArray) -> FloatArray:
    """One pose per scan from the poses at filter updates and the odometry in between.

    Scan ``k`` after the update at scan ``u`` is placed at ``best(u) + (odometry(u) -> odometry(k))``,
    which is how MRPT itself predicts the pose between updates (its accumulated odometry increment).
    ``best_path[0]`` is the filter's initial pose; ``best_path[j + 1]`` belongs to the ``j``-th update.
    """
    n = len(updated)
    if odometry.shape != (n, 3):
        raise BaselineError(f"odometry of shape {odometry.shape} for {n} scans")
    update_scans = np.flatnonzero(updated)
    if len(best_path) != len(update_scans) + 1:
        raise BaselineError(f"{len(best_path)} path poses for {len(update_scans)} filter updates")
    owner = np.cumsum(updated) - 1  # index of the last update at or before each scan
    anchor_scan = update_scans[owner]
    anchor_pose = best_path[owner + 1]
    steps = se2.between(odometry[anchor_scan], odometry)
    return se2.compose(anchor_pose, steps)


# -- occupancy grid --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class GridMap:
    """The final most likely occupancy grid: ``free`` probability per cell, row 0 at ``y_max``."""

    free: NDArray[np.float32]
    x_min: float
    x_max: float
    y_min: float
    y_max: float

    @property
    def resolution_m(self) -> float:
        resolution: float = (self.x_max - self.x_min) / self.free.shape[1]
        return resolution

    def occupied_points(self, probability: float) -> FloatArray:
        """Centres ``(K, 2)`` of the cells whose occupancy probability is at least ``probability``."""
        rows, cols = np.nonzero(self.free <= 1.0 - probability)
        res = self.resolution_m
        return np.column_stack([self.x_min + (cols + 0.5) * res, self.y_max - (rows + 0.5) * res])

    def summary(self) -> dict[str, float | int]:
        return {
            "resolution_m": self.resolution_m,
            "x_min": self.x_min,
            "x_max": self.x_max,
            "y_min": self.y_min,
            "y_max": self.y_max,
            "width_cells": int(self.free.shape[1]),
            "height_cells": int(self.free.shape[0]),
        }


def grid_map(out_dir: Path, expected_resolution_m: float) -> GridMap:
    """The final grid image and its limits; the cell size must be the configured resolution."""
    import matplotlib.image as mpimg

    image_path, limits_path = out_dir / GRID_IMAGE, out_dir / GRID_LIMITS
    limits = read_rows(limits_path, 4, "grid limits")
    if len(limits) != 1:
        raise BaselineError(f"{limits_path}: {len(limits)} rows; expected one (x_min x_max y_min y_max)")
    if not image_path.is_file():
        raise BaselineError(f"{image_path}: missing; rbpf-slam did not write its grid map")
    image = np.asarray(mpimg.imread(image_path), dtype=np.float32)
    if image.ndim == 3:  # a grey image stored with colour channels
        image = image[..., :3].mean(axis=2)
    x_min, x_max, y_min, y_max = (float(v) for v in limits[0])
    grid = GridMap(free=image, x_min=x_min, x_max=x_max, y_min=y_min, y_max=y_max)
    res_y = (y_max - y_min) / image.shape[0]
    if not np.isclose(grid.resolution_m, expected_resolution_m, rtol=1e-3) or not np.isclose(
        res_y, expected_resolution_m, rtol=1e-3
    ):
        raise BaselineError(
            f"{image_path}: {image.shape[1]} x {image.shape[0]} cells over the limits in {limits_path} give "
            f"{grid.resolution_m:.4g} x {res_y:.4g} m cells; expected {expected_resolution_m} m"
        )
    return grid
