"""Trajectory files: planar poses in the formats other tools write (TUM, KITTI, corrected CARMEN logs).

Run folders store their trajectories as TUM files (``t x y z qx qy qz qw``),
written with z = 0 and a yaw-only quaternion, 9 decimals, so that evo and
other tools read them directly. ``albot1 evaluate --trajectory`` reads a
trajectory from another tool (Cartographer, slam_toolbox, GMapping) to score
it with this suite's metrics:

``tum``
    ``t x y z qx qy qz qw`` per line, ``#`` comments; the heading is the yaw
    of the quaternion (any roll or pitch is ignored: the poses are planar).
``kitti``
    12 numbers per line, the row-major 3x4 matrix ``[R | t]`` of each pose,
    no timestamps (one pose per scan, in order). The poses must lie in the
    x-y plane (z up), as a 2D SLAM system exports them; poses moving in the
    x-z plane (the KITTI camera frame) are refused with that explanation.
``carmen``
    a CARMEN log whose laser lines carry corrected poses (the
    ``radish-corrected`` logs, GMapping's output): each front-laser line's
    robot pose (the loader's ``reference="laser-pose"``) at its timestamp.

Every parse error names the file and line, what was found and what was
expected (:class:`~albot1.data.errors.ParseError`).
"""

from __future__ import annotations

import io
import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Literal, get_args

import numpy as np
from numpy.typing import NDArray

from albot1.data.errors import DataError, ParseError

TrajectoryFormat = Literal["tum", "kitti", "carmen"]
TRAJECTORY_FORMATS: tuple[TrajectoryFormat, ...] = get_args(TrajectoryFormat)
TUM_COLUMNS = "t x y z qx qy qz qw"
#: Suffixes of CARMEN logs (plain or compressed) for :func:`guess_format`.
CARMEN_SUFFIXES = (".clf", ".log", ".gfs", ".carmen")


@dataclass(frozen=True)
class PoseFile:
    """Poses read from a trajectory file: ``(N, 3)`` x, y (m), yaw (rad); timestamps (s) or None (KITTI)."""

    path: Path
    format: TrajectoryFormat
    poses: NDArray[np.float64]
    timestamps: NDArray[np.float64] | None


def _tum_rows(timestamps: NDArray[np.float64], poses: NDArray[np.float64]) -> NDArray[np.float64]:
    half = poses[:, 2] / 2.0
    zeros = np.zeros(len(poses))
    return np.column_stack([timestamps, poses[:, 0], poses[:, 1], zeros, zeros, zeros, np.sin(half), np.cos(half)])


def _planar(rows: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(N, 3)`` x, y, yaw of TUM rows (the yaw of the quaternion)."""
    qx, qy, qz, qw = rows[:, 4], rows[:, 5], rows[:, 6], rows[:, 7]
    yaw = np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return np.column_stack([rows[:, 1], rows[:, 2], yaw])


def write_tum(path: Path | IO[str], timestamps: NDArray[np.float64], poses: NDArray[np.float64]) -> None:
    """Write planar poses as TUM (z = 0, yaw-only quaternion, 9 decimals)."""
    np.savetxt(path, _tum_rows(timestamps, poses), fmt="%.9f", header="timestamp x y z qx qy qz qw", comments="# ")


def as_stored(timestamps: NDArray[np.float64], poses: NDArray[np.float64]) -> NDArray[np.float64]:
    """``poses`` exactly as a TUM file of this module stores them (9 decimals, the heading via its quaternion).

    Run folders hold their reference poses in this form (``reference.tum``);
    scoring an external trajectory against the same form gives the same
    numbers digit for digit, even where a metric compares travelled
    distance with a threshold (RPE pairs every metre).
    """
    buffer = io.StringIO()
    write_tum(buffer, timestamps, poses)
    buffer.seek(0)
    return _planar(np.loadtxt(buffer, ndmin=2, comments="#", dtype=float).reshape(-1, 8))


def _rows(path: Path, columns: int, expected: str) -> NDArray[np.float64]:
    """The numeric rows of a whitespace-separated text file with ``columns`` numbers per line.

    The common case is one fast ``numpy.loadtxt``; when it fails the file
    is read line by line to name the first offending line.
    """
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data": an empty file is no poses
            rows = np.loadtxt(path, ndmin=2, comments="#", dtype=float)
    except OSError as exc:
        raise DataError(f"{path}: cannot read the trajectory: {exc.strerror or exc}") from None
    except ValueError:
        rows = None
    if rows is not None and (rows.size == 0 or rows.shape[1] == columns) and np.isfinite(rows).all():
        return rows.reshape(-1, columns)
    _locate_problem(path, columns, expected)
    raise ParseError(path, f"not a {expected} file")  # _locate_problem always raises first


def _locate_problem(path: Path, columns: int, expected: str) -> None:
    with path.open(encoding="utf-8", errors="replace") as lines:
        for number, line in enumerate(lines, start=1):
            text = line.split("#", 1)[0].strip()
            if not text:
                continue
            fields = text.split()
            if len(fields) != columns:
                raise ParseError(
                    path, f"found {len(fields)} values, expected {columns} ({expected})", line=number
                ) from None
            for position, field in enumerate(fields, start=1):
                try:
                    value = float(field)
                except ValueError:
                    raise ParseError(
                        path, f"value {position} is {field[:40]!r}, expected a number", line=number
                    ) from None
                if not math.isfinite(value):
                    raise ParseError(path, f"value {position} is {field!r}, expected a finite number", line=number)


def read_tum(path: Path) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(timestamps, poses)`` of a TUM file; the heading is the yaw of the quaternion.

    A quaternion of (near) zero length has no rotation: a ParseError naming its line.
    """
    path = Path(path)
    rows = _rows(path, 8, f"TUM trajectory: {TUM_COLUMNS}")
    bad = np.flatnonzero(np.linalg.norm(rows[:, 4:8], axis=1) < 1e-6)
    if len(bad):
        raise ParseError(
            path, "quaternion (qx qy qz qw) has zero length, expected a rotation", line=_line_of(path, bad[0])
        )
    return rows[:, 0], _planar(rows)


def read_kitti(path: Path) -> NDArray[np.float64]:
    """``(N, 3)`` planar poses of a KITTI pose file (3x4 row-major ``[R | t]`` per line, x-y plane)."""
    path = Path(path)
    rows = _rows(path, 12, "KITTI poses: the 12 numbers of a 3x4 matrix [R | t] per line")
    if not len(rows):
        return np.empty((0, 3))
    tx, ty, tz = rows[:, 3], rows[:, 7], rows[:, 11]
    spread_y, spread_z = float(np.ptp(ty)), float(np.ptp(tz))
    if spread_z > 1e-3 and spread_y < 0.1 * spread_z:
        raise ParseError(
            path,
            f"the poses move {spread_z:.3g} m along z but {spread_y:.3g} m along y: this looks like "
            "KITTI's camera frame (x-z plane); expected planar poses in the x-y plane (z up)",
            line=1,
        )
    yaw = np.arctan2(rows[:, 4], rows[:, 0])  # R[1, 0], R[0, 0]
    return np.column_stack([tx, ty, yaw])


def read_carmen_poses(path: Path) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(timestamps, poses)``: the corrected robot pose of every front-laser line of a CARMEN log."""
    from albot1.data.loaders.registry import load

    sequence = load(Path(path), "carmen", reference="laser-pose")
    arrays = sequence.arrays
    if arrays.reference is None:  # pragma: no cover - laser-pose gives every scan a pose
        raise DataError(f"{path}: the log's laser lines carry no poses")
    return arrays.timestamps, arrays.reference


def guess_format(path: Path) -> TrajectoryFormat:
    """The format of a trajectory file from its name, else from its first data line (8 or 12 numbers)."""
    name = path.name.lower()
    for compressed in (".gz", ".bz2"):
        name = name.removesuffix(compressed)
    if name.endswith(CARMEN_SUFFIXES):
        return "carmen"
    if name.endswith(".tum"):
        return "tum"
    if name.endswith(".kitti"):
        return "kitti"
    try:
        with path.open(encoding="utf-8", errors="replace") as lines:
            for line in lines:
                text = line.split("#", 1)[0].strip()
                if text:
                    count = len(text.split())
                    if count == 8:
                        return "tum"
                    if count == 12:
                        return "kitti"
                    break
    except OSError as exc:
        raise DataError(f"{path}: cannot read the trajectory: {exc.strerror or exc}") from None
    raise DataError(
        f"{path}: cannot tell the trajectory format from its name or first line; "
        f"expected {' | '.join(TRAJECTORY_FORMATS)} (give --format)"
    )


def read_trajectory(path: str | Path, format_name: str | None = None) -> PoseFile:
    """Read a trajectory file in ``format_name`` (guessed from the file when None)."""
    file = Path(path)
    if not file.is_file():
        raise DataError(f"{file}: trajectory file not found")
    if format_name is not None and format_name not in TRAJECTORY_FORMATS:
        raise DataError(f"trajectory format {format_name!r} not known; expected {' | '.join(TRAJECTORY_FORMATS)}")
    fmt: TrajectoryFormat = format_name if format_name is not None else guess_format(file)
    if fmt == "kitti":
        return PoseFile(file, fmt, read_kitti(file), None)
    stamps, poses = read_tum(file) if fmt == "tum" else read_carmen_poses(file)
    return PoseFile(file, fmt, poses, stamps)


def _line_of(path: Path, row: int) -> int:
    """The 1-based line number of data row ``row`` (comments and blank lines skipped)."""
    seen = -1
    with path.open(encoding="utf-8", errors="replace") as lines:
        for number, line in enumerate(lines, start=1):
            if line.split("#", 1)[0].strip():
                seen += 1
                if seen == row:
                    return number
    return seen + 1
