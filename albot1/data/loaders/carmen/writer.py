"""Writes a Sequence as a CARMEN log that :class:`CarmenLoader` reads back unchanged.

Why ROBOTLASER1 and not FLASER: only ROBOTLASER1 carries the beam geometry
(start angle, angular resolution) and the sensor's max range, so scans of any
field of view round-trip without guessing. Per frame the writer emits::

    ODOM x y theta 0 0 0                     (the odometry, for tools that read ODOM)
    TRUEPOS ref_x ref_y ref_theta x y theta  (only when the frame has a reference pose)
    ROBOTLASER1 ... laser pose = odometry * sensor_offset, robot pose = odometry ...

all stamped with the scan's timestamp. A no-return beam (NaN) is written as
the max range (a 0 m reading as 0, CARMEN's "no reading"), which the loader's no-return
rule turns back into NaN. A return
within the rule's 5 mm of the max range (a bag reading equal to ``range_max``)
would come back as no return too, so the line then declares a max range raised
just above its longest return (by at most 6 mm, :func:`_declared_max_range`);
a positive return that prints as 0 is refused. Ranges
are written with 6 decimals (1 um), poses with 9, timestamps with 6, the beam
geometry with 17 significant digits (so angles come back to 1e-15 rad).

Every frame is checked with the reader's own rules (:mod:`.checks`: beam
count, ranges, beam geometry, finite poses and stamps, stamps not going back
more than the loader's default tolerance) before it is written, so the writer
never produces a log its reader refuses. A range above the max range is
refused too: it would come back as "no return".

The output is compressed when the name ends in ``.gz`` or ``.bz2`` and is
written to a temporary file renamed into place, so a failed conversion
leaves no partial log behind (output rules: :mod:`albot1.data.loaders.output`).
"""

from __future__ import annotations

import bz2
import gzip
import math
from pathlib import Path
from typing import IO, ClassVar

import numpy as np

from albot1.atomic import atomic_write
from albot1.data.errors import UnwritableError
from albot1.data.loaders.base import reference_presence_problem
from albot1.data.loaders.carmen.checks import beam_count_problem, geometry_problem, ranges_problem, time_problem
from albot1.data.loaders.carmen.geometry import NO_RETURN_MARGIN
from albot1.data.loaders.output import prepare_output, writing
from albot1.data.model import Frame, Scan, Sequence, mount_problem
from albot1.geometry import se2

HOST = "albot1"
_HEADER = """# CARMEN Logfile written by albot1-bench (albot1.data.loaders.carmen.writer)
# file format is one message per line
# message_name [message contents] ipc_timestamp ipc_hostname logger_timestamp
# message formats defined: PARAM ODOM TRUEPOS ROBOTLASER1
# ODOM x y theta tv rv accel
# TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta
# ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy remission_mode
#   num_readings [range_readings] num_remissions [remission values] laser_pose_x laser_pose_y laser_pose_theta
#   robot_pose_x robot_pose_y robot_pose_theta laser_tv laser_rv forward_safety_dist side_safty_dist turn_axis
"""
#: Relative tolerance on beam spacing: ROBOTLASER1 can only describe evenly spaced beams.
_SPACING_TOLERANCE = 1e-6
#: The loader's default ``time_tolerance`` (seconds a scan stamp may go back): what the writer allows.
DEFAULT_TIME_TOLERANCE = 1.0


def _open(path: Path) -> IO[str]:
    if path.name.endswith(".gz"):
        return gzip.open(path, "wt", encoding="ascii", compresslevel=6)
    if path.name.endswith(".bz2"):
        return bz2.open(path, "wt", encoding="ascii")
    return path.open("w", encoding="ascii")


def _pose(p: np.ndarray) -> str:
    return f"{p[0]:.9f} {p[1]:.9f} {p[2]:.9f}"


def _frame_problem(frame: Frame, step: float) -> str | None:
    """Why the reader would refuse (or change) this frame as a ROBOTLASER1 line; None if it would not."""
    scan = frame.scan
    n = scan.beams
    problem = beam_count_problem(n)
    if problem is not None:
        return problem
    if not np.isfinite(scan.angles).all():
        return "beam angles must be finite numbers (radians)"
    if n > 2 and not np.allclose(np.diff(scan.angles), step, rtol=_SPACING_TOLERANCE, atol=1e-9):
        return (
            "beam angles are not evenly spaced; a CARMEN ROBOTLASER1 line needs a start angle and one angular "
            "resolution"
        )
    max_range = float(scan.max_range)
    if not (math.isfinite(max_range) and max_range > 0):
        return f"max_range {max_range!r}; expected a positive number of metres"
    if float(f"{max_range:.6f}") <= 0:
        return f"max_range {max_range!r} rounds to 0 in the log's 6 decimals (which means 'not stated')"
    returns = _returns(scan.ranges)
    declared = _declared_max_range(scan)
    found = geometry_problem(n, *(np.array([float(v)]) for v in (scan.angles[0], step * (n - 1), step, declared)))
    if found is None:  # the ranges as written: 6 decimals, no return as the declared max range
        written: np.ndarray = np.round(np.where(returns, scan.ranges, declared), 6)
        found = ranges_problem(written[None, :])
    if found is not None:
        return found[1]
    longest = float(np.nanmax(scan.ranges)) if not np.isnan(scan.ranges).all() else 0.0
    if longest > max_range:
        return f"a range of {longest!r} m exceeds max_range {max_range!r} m (it would come back as no return)"
    vanishing = (scan.ranges > 0) & (written <= 0)
    if vanishing.any():
        k = int(np.argmax(vanishing))
        return (
            f"range {k + 1} of {n} is {float(scan.ranges[k])!r} m, which prints as 0 in the log's 6 decimals and "
            f"would come back as no return (a return at 0 m is impossible; NaN means no return)"
        )
    values = [scan.timestamp, *np.asarray(frame.odometry, dtype=np.float64).tolist()]
    if frame.reference is not None:
        values += np.asarray(frame.reference, dtype=np.float64).tolist()
    if not all(math.isfinite(v) for v in values):
        return f"the timestamp and poses must be finite numbers, got {values}"
    return None


def _returns(ranges: np.ndarray) -> np.ndarray:
    """Which beams are written as they are: all but NaN (no return), written as the max range. A 0 m reading
    is written as 0, CARMEN's "no reading", which the reader takes as no return too (and refuses a line of
    nothing else: a dead laser); an infinite or negative range is written for the checks to refuse."""
    returns: np.ndarray = ~np.isnan(ranges)
    return returns


def _declared_max_range(scan: Scan) -> float:
    """The max range the line declares: the scan's, or raised just enough that every return stays a return.

    The reader takes ``r >= max_range - NO_RETURN_MARGIN`` as no return (a logged maximum printed with
    CARMEN's 1 cm resolution), so a return within 5 mm of the max range (one equal to a bag's
    ``range_max``, say) would come back as no return. The declared max range is then raised to the longest
    printed return plus 6 mm, rounded up to the printed micrometre: every return reads back below it, and
    the no-returns written at it read back as no return. It moves by at most 6 mm.
    """
    max_range = float(scan.max_range)
    ranges = scan.ranges[_returns(scan.ranges)]
    returns = ranges[(ranges > 0) & (ranges <= max_range)]  # others are refused by the checks
    if not returns.size:
        return max_range
    longest = float(np.round(returns.max(), 6))
    if longest < max_range - NO_RETURN_MARGIN - 1e-6:
        return max_range
    return max(max_range, math.ceil((longest + NO_RETURN_MARGIN + 0.001) * 1e6) / 1e6)


def _laser_line(frame: Frame, offset: np.ndarray) -> str:
    scan = frame.scan
    n = scan.beams
    angles = scan.angles
    step = float(angles[1] - angles[0]) if n > 1 else 0.0
    problem = _frame_problem(frame, step)
    if problem is not None:
        raise UnwritableError(f"frame {frame.index}: {problem}; the CARMEN reader would refuse it")
    max_range = _declared_max_range(scan)
    ranges = np.where(_returns(scan.ranges), scan.ranges, max_range)
    robot = np.asarray(frame.odometry, dtype=np.float64)
    laser = se2.compose(robot, offset)
    stamp = f"{scan.timestamp:.6f}"
    fov = step * (n - 1) if n > 1 else 0.0
    return (
        f"ROBOTLASER1 0 {float(angles[0]):.17g} {fov:.17g} {step:.17g} {max_range:.6f} 0.010000 0 {n} "
        + ("%.6f " * n) % tuple(ranges.tolist())
        + f"0 {_pose(laser)} {_pose(robot)} 0.000000 0.000000 0.000000 0.000000 0.000000 "
        + f"{stamp} {HOST} {stamp}\n"
    )


class CarmenWriter:
    """``albot1 convert IN OUT.clf[.gz|.bz2] --format carmen``."""

    format_name: ClassVar[str] = "carmen"

    def write(self, sequence: Sequence, path: Path) -> None:
        path = prepare_output(path)
        offset = np.asarray(sequence.metadata.sensor_offset, dtype=np.float64)
        mount = mount_problem((float(offset[0]), float(offset[1]), float(offset[2])))  # the reader's own rule
        if mount is not None:
            raise UnwritableError(f"{path}: {mount}")
        latest = -math.inf

        def write_lines(tmp: Path) -> None:
            with _open(tmp) as out:
                out.write(_HEADER)
                out.write(f"PARAM robot_frontlaser_offset {offset[0]:.9f} 0.000000 {HOST} 0.000000\n")
                out.write(f"PARAM robot_frontlaser_side_offset {offset[1]:.9f} 0.000000 {HOST} 0.000000\n")
                out.write(f"PARAM robot_frontlaser_angular_offset {offset[2]:.9f} 0.000000 {HOST} 0.000000\n")
                nonlocal latest
                first: Frame | None = None
                for frame in sequence.frames():
                    first = first or frame
                    back = time_problem(latest, frame.scan.timestamp, DEFAULT_TIME_TOLERANCE)
                    if back is not None:
                        raise UnwritableError(f"frame {frame.index}: scan {back}; the CARMEN reader would refuse it")
                    gap = reference_presence_problem(first, frame, "a CARMEN log (TRUEPOS lines)")
                    if gap is not None:
                        raise UnwritableError(gap)
                    latest = max(latest, frame.scan.timestamp)
                    stamp = f"{frame.scan.timestamp:.6f}"
                    out.write(f"ODOM {_pose(frame.odometry)} 0 0 0 {stamp} {HOST} {stamp}\n")
                    if frame.reference is not None:
                        out.write(f"TRUEPOS {_pose(frame.reference)} {_pose(frame.odometry)} {stamp} {HOST} {stamp}\n")
                    out.write(_laser_line(frame, offset))
                if latest == -math.inf:
                    raise UnwritableError("the sequence has no scans; the CARMEN reader refuses a log without scans")

        try:
            with writing(path):
                atomic_write(path, write_lines)
        except UnwritableError as exc:
            raise UnwritableError(f"{path}: {exc}") from None
