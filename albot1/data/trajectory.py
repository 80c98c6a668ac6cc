"""Trajectory files: planar poses in the formats other tools write (TUM, KITTI, corrected CARMEN logs).

Run folders store their trajectories as TUM files (``t x y z qx qy qz qw``),
written with z = 0 and a yaw-only quaternion, 9 decimals, so that evo and
other tools read them directly. ``albot1 evaluate --trajectory`` reads a
trajectory from another tool (Cartographer, slam_toolbox, GMapping) to score
it with this suite's metrics:

``tum``
    ``t x y z qx qy qz qw`` per line, ``#`` comments; the heading is the yaw
    of the quaternion (a small roll or pitch is ignored: the poses are planar;
    a tilt beyond :data:`MAX_TILT_DEG` is refused).
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
expected (:class:`~albot1.data.errors.ParseError`). What is refused, and why:

* a timestamp beyond :data:`MAX_TIMESTAMP_S` (not seconds);
* a value that is not a finite number, or a coordinate beyond
  :data:`MAX_COORDINATE_M` (1e8 m, 100 000 km: no planar map is that large,
  and larger values overflow to infinity once squared in a metric);
* a TUM quaternion whose length is not within :data:`QUATERNION_TOLERANCE`
  of 1 (0.99-1.01): a small deviation (the rounding of a file written with
  few decimals) is normalised away, a larger one means the four numbers are
  not a unit quaternion (another column order, or no rotation at all) and
  reading a heading from them would be a guess;
* a TUM quaternion tilting the pose more than :data:`MAX_TILT_DEG` from
  upright: the heading of a planar pose is its turn about z, and a yaw-only
  quaternion written w first (``qw qx qy qz``) reads as a roll whose yaw is 0;
* a KITTI matrix whose 3x3 part is not a rotation (``R R^T`` off the
  identity by more than :data:`ROTATION_TOLERANCE`, or a reflection);
* (:func:`read_trajectory`) two poses with one timestamp: which of the two
  is meant cannot be told, so both line numbers are named.

A byte-order mark at the start of a file is dropped (:mod:`albot1.data.text`).
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
from albot1.data.model import MAX_COORDINATE_M, MAX_TIMESTAMP_S
from albot1.data.text import TEXT_ENCODING
from albot1.data.tokens import is_number

TrajectoryFormat = Literal["tum", "kitti", "carmen"]
TRAJECTORY_FORMATS: tuple[TrajectoryFormat, ...] = get_args(TrajectoryFormat)
TUM_COLUMNS = "t x y z qx qy qz qw"
#: Suffixes of CARMEN logs (plain or compressed) for :func:`guess_format`.
CARMEN_SUFFIXES = (".clf", ".log", ".gfs", ".carmen")
#: Largest accepted | |q| - 1 | of a TUM quaternion; within it the quaternion is normalised.
QUATERNION_TOLERANCE = 1e-2
#: Largest accepted tilt (deg) of a TUM pose's z axis from the world's: a planar robot's base is upright
#: (a ramp is a few degrees); beyond it the quaternion's yaw is no heading (:func:`_check_tilt`).
MAX_TILT_DEG = 45.0
#: Largest accepted entry of ``R R^T - I`` of a KITTI rotation.
ROTATION_TOLERANCE = 1e-2


@dataclass(frozen=True)
class PoseFile:
    """Poses read from a trajectory file: ``(N, 3)`` x, y (m), yaw (rad); timestamps (s) or None (KITTI)."""

    path: Path
    format: TrajectoryFormat
    poses: NDArray[np.float64]
    timestamps: NDArray[np.float64] | None


#: One TUM line as :func:`write_tum` writes it: z, qx and qy of a planar pose are 0, which ``%.9f`` always spells
#: ``0.000000000`` (``numpy.savetxt(fmt="%.9f")`` wrote these files until session 26, byte for byte the same).
_TUM_LINE = "%.9f %.9f %.9f 0.000000000 0.000000000 0.000000000 %.9f %.9f\n"
_TUM_HEADER = "# timestamp x y z qx qy qz qw\n"


def _planar(rows: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(N, 3)`` x, y, yaw of TUM rows (the yaw of the quaternion)."""
    qx, qy, qz, qw = rows[:, 4], rows[:, 5], rows[:, 6], rows[:, 7]
    yaw = np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return np.column_stack([rows[:, 1], rows[:, 2], yaw])


def write_tum(path: Path | IO[str], timestamps: NDArray[np.float64], poses: NDArray[np.float64]) -> None:
    """Write planar poses as TUM (z = 0, yaw-only quaternion, 9 decimals).

    One ``%`` of the whole file's format over the values as Python floats: ``numpy.savetxt`` formatted a row at a
    time from numpy scalars, ~6 us a line, and every run folder holds two or three of these files (13,631 lines
    each on intel); the text is the same (the same ``%.9f`` of the same doubles, the zero columns written as
    ``%.9f`` writes 0.0).
    """
    poses = np.asarray(poses, dtype=float).reshape(-1, 3)
    half = poses[:, 2] / 2.0
    values = np.column_stack(
        [np.asarray(timestamps, dtype=float), poses[:, 0], poses[:, 1], np.sin(half), np.cos(half)]
    )
    text = _TUM_HEADER + (_TUM_LINE * len(values)) % tuple(values.ravel().tolist())
    if isinstance(path, (str, Path)):
        # text mode as numpy.savetxt opened a path (its encoding was the locale's; the text is ASCII either way);
        # UTF-8, whose codec every process has imported, not latin-1, which a forked cell would import itself
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(text)
    else:
        path.write(text)


def as_stored(timestamps: NDArray[np.float64], poses: NDArray[np.float64]) -> NDArray[np.float64]:
    """``poses`` exactly as a TUM file of this module stores them (9 decimals, the heading via its quaternion).

    Run folders hold their reference poses in this form (``reference.tum``);
    scoring an external trajectory against the same form gives the same
    numbers digit for digit, even where a metric compares travelled
    distance with a threshold (RPE pairs every metre).
    """
    return _planar(_stored_rows(timestamps, poses))


def stamps_as_stored(timestamps: NDArray[np.float64]) -> NDArray[np.float64]:
    """``timestamps`` exactly as a TUM file of this module stores them (9 decimals): a run's ``trajectory.tum``."""
    return _stored_rows(timestamps, np.zeros((len(timestamps), 3)))[:, 0]


def _stored_rows(timestamps: NDArray[np.float64], poses: NDArray[np.float64]) -> NDArray[np.float64]:
    buffer = io.StringIO()
    write_tum(buffer, timestamps, poses)
    buffer.seek(0)
    return np.loadtxt(buffer, ndmin=2, comments="#", dtype=float).reshape(-1, 8)


def _rows(path: Path, columns: int, expected: str) -> NDArray[np.float64]:
    """The numeric rows of a whitespace-separated text file with ``columns`` numbers per line.

    The common case is one fast ``numpy.loadtxt``; when it fails the file
    is read line by line to name the first offending line.
    """
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data": an empty file is no poses
            rows = np.loadtxt(path, ndmin=2, comments="#", dtype=float, encoding=TEXT_ENCODING)
    except OSError as exc:
        raise DataError(f"{path}: cannot read the trajectory: {exc.strerror or exc}") from None
    except ValueError:
        rows = None
    if rows is not None and (rows.size == 0 or rows.shape[1] == columns) and np.isfinite(rows).all():
        return rows.reshape(-1, columns)
    _locate_problem(path, columns, expected)
    raise ParseError(path, f"not a {expected} file")  # _locate_problem always raises first


def _locate_problem(path: Path, columns: int, expected: str) -> None:
    with path.open(encoding=TEXT_ENCODING, errors="replace") as lines:
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
                # the project's one number test: numpy's bulk read refuses what float() alone would take
                # (``0_0.8``), so this pass must refuse it too, or the error could name no line
                if not is_number(field):
                    raise ParseError(path, f"value {position} is {field[:40]!r}, expected a number", line=number)
                if not math.isfinite(float(field)):
                    raise ParseError(path, f"value {position} is {field!r}, expected a finite number", line=number)


def read_tum(path: Path) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(timestamps, poses)`` of a TUM file; the heading is the yaw of the quaternion.

    A quaternion whose length is off 1 by more than :data:`QUATERNION_TOLERANCE`
    is a ParseError naming its line; smaller deviations are normalised.
    """
    path = Path(path)
    rows = _rows(path, 8, f"TUM trajectory: {TUM_COLUMNS}")
    late = np.flatnonzero(np.abs(rows[:, 0]) > MAX_TIMESTAMP_S)
    if len(late):
        raise ParseError(
            path,
            f"timestamp {rows[late[0], 0]:.6g} is beyond {MAX_TIMESTAMP_S:g}; expected seconds "
            "(a timestamp in micro- or nanoseconds must be divided first)",
            line=_line_of(path, int(late[0])),
        )
    _check_coordinates(path, rows[:, 1:3])
    norm = np.linalg.norm(rows[:, 4:8], axis=1)
    bad = np.flatnonzero(~(np.abs(norm - 1.0) <= QUATERNION_TOLERANCE))
    if len(bad):
        raise ParseError(
            path,
            f"quaternion (qx qy qz qw) has length {norm[bad[0]]:.6g}; expected a unit quaternion "
            f"(length within {QUATERNION_TOLERANCE:g} of 1)",
            line=_line_of(path, int(bad[0])),
        )
    # Normalise only where it matters, so the files this module writes (|q| within ~1e-9 of 1) read back
    # bit for bit as before (run folders, fingerprints).
    rescale = np.abs(norm - 1.0) > 1e-6
    rows[rescale, 4:8] /= norm[rescale, None]
    _check_tilt(path, rows)
    return rows[:, 0], _planar(rows)


def _check_tilt(path: Path, rows: NDArray[np.float64]) -> None:
    """ParseError naming the first TUM line whose (unit) quaternion tilts the pose beyond :data:`MAX_TILT_DEG`.

    The heading is read as the yaw of the quaternion, which is the heading only of a pose turned (nearly)
    about z. A yaw-only quaternion written w first (``qw qx qy qz``, Eigen's coefficient order) reads as a
    roll of up to 180 deg whose yaw is 0 whatever the robot's heading: every rotation metric was silently
    scored against a heading of 0. The tilt is the angle between the pose's z axis and the world's.
    """
    qx, qy = rows[:, 4], rows[:, 5]
    tilt = np.degrees(np.arccos(np.clip(1.0 - 2.0 * (qx * qx + qy * qy), -1.0, 1.0)))
    bad = np.flatnonzero(tilt > MAX_TILT_DEG)
    if len(bad):
        row = int(bad[0])
        q = ", ".join(f"{v:.6g}" for v in rows[row, 4:8])
        raise ParseError(
            path,
            f"quaternion (qx qy qz qw) = ({q}) tilts the pose {tilt[row]:.1f} deg from upright; expected a planar "
            f"pose, turned about z (tilt at most {MAX_TILT_DEG:g} deg); a quaternion written w first "
            "(qw qx qy qz) reads so: TUM's order is qx qy qz qw",
            line=_line_of(path, row),
        )


def _check_coordinates(path: Path, xy: NDArray[np.float64]) -> None:
    """ParseError naming the first line whose x or y is beyond :data:`MAX_COORDINATE_M`."""
    bad = np.flatnonzero(np.abs(xy).max(axis=1, initial=0.0) > MAX_COORDINATE_M)
    if len(bad):
        row = int(bad[0])
        raise ParseError(
            path,
            f"position ({xy[row, 0]:.6g}, {xy[row, 1]:.6g}) m is beyond {MAX_COORDINATE_M:g} m; "
            "expected coordinates of a map in metres",
            line=_line_of(path, row),
        )


def _check_rotations(path: Path, rows: NDArray[np.float64]) -> None:
    """ParseError naming the first KITTI line whose 3x3 part is not a rotation matrix."""
    rotations = rows[:, [0, 1, 2, 4, 5, 6, 8, 9, 10]].reshape(-1, 3, 3)
    off = np.abs(rotations @ rotations.transpose(0, 2, 1) - np.eye(3)).max(axis=(1, 2))
    det = np.linalg.det(rotations)
    bad = np.flatnonzero(~((off <= ROTATION_TOLERANCE) & (det > 0)))
    if len(bad):
        row = int(bad[0])
        raise ParseError(
            path,
            f"the 3x3 part of [R | t] is not a rotation (R R^T differs from the identity by {off[row]:.3g}, "
            f"det {det[row]:.3g}); expected an orthonormal matrix with determinant 1",
            line=_line_of(path, row),
        )


def read_kitti(path: Path) -> NDArray[np.float64]:
    """``(N, 3)`` planar poses of a KITTI pose file (3x4 row-major ``[R | t]`` per line, x-y plane)."""
    path = Path(path)
    rows = _rows(path, 12, "KITTI poses: the 12 numbers of a 3x4 matrix [R | t] per line")
    if not len(rows):
        return np.empty((0, 3))
    _check_coordinates(path, rows[:, [3, 7]])
    _check_rotations(path, rows)
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
    poses = arrays.reference
    bad = np.flatnonzero(~(np.isfinite(poses).all(axis=1) & (np.abs(poses[:, :2]).max(axis=1) <= MAX_COORDINATE_M)))
    if len(bad):
        row = int(bad[0])
        raise ParseError(
            path,
            f"laser line {row} (0-based, t = {arrays.timestamps[row]:.6f} s): pose ({poses[row, 0]:.6g}, "
            f"{poses[row, 1]:.6g}, {poses[row, 2]:.6g}) is not finite or beyond {MAX_COORDINATE_M:g} m; "
            "expected metres of a map",
        )
    return arrays.timestamps, poses


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
        with path.open(encoding=TEXT_ENCODING, errors="replace") as lines:
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


def read_trajectory(path: str | Path, format_name: str | None = None, *, repeated_stamps: bool = False) -> PoseFile:
    """Read a trajectory file in ``format_name`` (guessed from the file when None).

    Two poses with one timestamp are refused (:func:`refuse_repeated_stamps`) unless ``repeated_stamps``:
    a caller that pairs the poses by line, not by time, checks them itself.
    """
    file = Path(path)
    if file.is_dir():
        raise DataError(f"{file}: is a folder; expected a trajectory file ({' | '.join(TRAJECTORY_FORMATS)})")
    if not file.exists():
        raise DataError(f"{file}: trajectory file not found")
    if not file.is_file():
        raise DataError(f"{file}: not a regular file; expected a trajectory file ({' | '.join(TRAJECTORY_FORMATS)})")
    if format_name is not None and format_name not in TRAJECTORY_FORMATS:
        raise DataError(f"trajectory format {format_name!r} not known; expected {' | '.join(TRAJECTORY_FORMATS)}")
    fmt: TrajectoryFormat = format_name if format_name is not None else guess_format(file)
    if fmt == "kitti":
        return PoseFile(file, fmt, read_kitti(file), None)
    stamps, poses = read_tum(file) if fmt == "tum" else read_carmen_poses(file)
    pose_file = PoseFile(file, fmt, poses, stamps)
    if not repeated_stamps:
        refuse_repeated_stamps(pose_file)
    return pose_file


def has_repeated_stamps(stamps: NDArray[np.float64] | None) -> bool:
    """Whether two of ``stamps`` are equal (None, a file without timestamps: no)."""
    return stamps is not None and len(np.unique(stamps)) < len(stamps)


def refuse_repeated_stamps(file: PoseFile) -> None:
    """ParseError naming both places of the first timestamp that two poses of ``file`` share.

    Matched by time, which of two poses at one time is meant cannot be
    told, and scoring either silently can be far off; the file must be fixed.
    """
    stamps = file.timestamps
    if stamps is None:
        return
    path = file.path
    order = np.argsort(stamps, kind="stable")
    same = np.flatnonzero(np.diff(stamps[order]) == 0)
    if not len(same):
        return
    first, second = sorted((int(order[same[0]]), int(order[same[0] + 1])))
    if file.format == "tum":
        first_line, second_line = _line_of(path, first), _line_of(path, second)
        raise ParseError(
            path,
            f"lines {first_line} and {second_line} both have timestamp {float(stamps[first])!r}; "
            "expected one pose per timestamp",
            line=second_line,
        )
    raise ParseError(
        path,
        f"scans {first} and {second} (0-based laser lines) both have timestamp {float(stamps[first])!r}; "
        "expected one pose per timestamp (a log whose timestamps repeat cannot place its poses in time)",
    )


def _line_of(path: Path, row: int) -> int:
    """The 1-based line number of data row ``row`` (comments and blank lines skipped)."""
    seen = -1
    with path.open(encoding=TEXT_ENCODING, errors="replace") as lines:
        for number, line in enumerate(lines, start=1):
            if line.split("#", 1)[0].strip():
                seen += 1
                if seen == row:
                    return number
    return seen + 1
