"""Non-finite and absurd numbers in a sequence's frames, refused with their location.

A log (CARMEN, ROS bag, own log) can carry ``inf``, ``nan`` or ``1e308``
where a pose is expected; such a value survives the parser (it is a
number) and ends as non-finite points of a map or an overflow in a metric.
Every frame a file loader yields passes :func:`checked` (applied by
:func:`albot1.data.open.open_sequence`), so the first offending scan is named
with its source, index and timestamp:

* odometry and reference poses: every component finite, and ``|x|, |y|``
  at most :data:`~albot1.data.model.MAX_COORDINATE_M` (the bound of trajectory files);
* the scan's timestamp finite and at most :data:`~albot1.data.model.MAX_TIMESTAMP_S`
  (the bound of trajectory files: a log stamped 1e300 s used to load and run, and
  then its own ``trajectory.tum`` was refused by ``albot1 evaluate``); its beam angles finite. Ranges may be NaN or
  infinite: loaders use those for "no return" (``docs/formats.md``); a
  kept reading is at most ``MAX_COORDINATE_M`` (a max range of 1e31 m lets 1e30 m through).

The sequence's laser mount (``metadata.sensor_offset``) is checked once, when it is opened
(:func:`~albot1.data.model.mount_problem`): finite and within
:data:`~albot1.data.model.MAX_MOUNT_M` of the robot's base, wherever the loader found it.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from albot1.data.errors import ParseError
from albot1.data.model import MAX_COORDINATE_M, MAX_TIMESTAMP_S, Frame, Sequence, mount_problem


def pose_problem(pose: object, what: str) -> str | None:
    """Why ``pose`` (x, y, theta) is not a usable pose, or None."""
    values = np.asarray(pose, dtype=float).reshape(-1)
    x, y, theta = (float(v) for v in values[:3]) if len(values) >= 3 else (math.nan,) * 3
    # plain float arithmetic: a sum is finite only when every term is (this runs once per scan)
    if math.isfinite(x + y + theta) and abs(x) <= MAX_COORDINATE_M and abs(y) <= MAX_COORDINATE_M:
        return None
    if not np.isfinite(values).all() or len(values) < 3:
        return f"{what} ({', '.join(f'{v:g}' for v in values)}) is not finite; expected finite numbers"
    return f"{what} position ({x:.6g}, {y:.6g}) m is beyond {MAX_COORDINATE_M:g} m; expected metres of a map"


def frame_problem(frame: Frame) -> str | None:
    """Why ``frame`` holds a value no method or metric can use, or None."""
    if not math.isfinite(frame.scan.timestamp):
        return f"timestamp {frame.scan.timestamp} is not finite"
    if abs(frame.scan.timestamp) > MAX_TIMESTAMP_S:
        return (
            f"timestamp {frame.scan.timestamp:.6g} is beyond {MAX_TIMESTAMP_S:g}; expected seconds "
            "(a stamp in micro- or nanoseconds must be divided first)"
        )
    problem = pose_problem(frame.odometry, "odometry")
    if problem is None and frame.reference is not None:
        problem = pose_problem(frame.reference, "reference pose")
    # radians sum to a finite number unless one of them is NaN or infinite
    if problem is None and not math.isfinite(float(frame.scan.angles.sum())):
        problem = "a beam angle is not finite; expected finite radians"
    if problem is None and not frame.scan.max_range <= MAX_COORDINATE_M:
        problem = _far_reading(frame.scan.ranges, frame.scan.max_range)
    return problem


def _far_reading(ranges: np.ndarray, max_range: float) -> str | None:
    """A kept reading beyond :data:`MAX_COORDINATE_M`, possible only when the scan's max range lets it through.

    A CARMEN ``ROBOTLASER1`` or a bag may declare a max range of 1e31 m; a
    reading of 1e30 m under it is no measurement, and its point would
    overflow the maps' grid arithmetic far from the line that holds it.
    Loaders turn readings beyond the max range into NaN, so the finite ones
    are the kept ones; the scalar test in :func:`frame_problem` keeps this
    off the per-scan path of every ordinary log.
    """
    with np.errstate(invalid="ignore"):
        far = np.flatnonzero(ranges > MAX_COORDINATE_M)
    if far.size == 0:
        return None
    k = int(far[0])
    return (
        f"range {k + 1} of {ranges.shape[0]} is {float(ranges[k]):.6g} m (max range {max_range:.6g} m), "
        f"expected at most {MAX_COORDINATE_M:g} m: no laser measures farther"
    )


def checked(sequence: Sequence) -> Sequence:
    """``sequence`` whose frames are checked as they stream by (ParseError naming source, scan and time).

    Its laser mount is checked at once: every scan is placed with it, so a wrong one is refused before
    any scan is read, with the loader's note of where it came from (a bag's ``/tf_static`` link, ...).
    """
    source = sequence.metadata.source or sequence.name
    mount = mount_problem(sequence.metadata.sensor_offset)
    if mount is not None:
        note = str(sequence.metadata.extra.get("sensor_offset_source") or "")
        raise ParseError(source, f"{mount}{f' (from {note})' if note else ''}")

    def check(frames: Iterator[Frame]) -> Iterator[Frame]:
        for frame in frames:
            problem = frame_problem(frame)
            if problem is not None:
                raise ParseError(source, f"scan {frame.index} (t = {frame.scan.timestamp:.6f} s): {problem}")
            yield frame

    return sequence.with_frames(check, scan_count=sequence.known_scan_count)
