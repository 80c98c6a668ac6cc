"""Small streamed transforms of a Sequence (prefix, stride, reference odometry, view spacing, sensor frame)."""

from __future__ import annotations

import itertools
import math
import sys
from collections.abc import Iterator
from dataclasses import replace

import numpy as np

from albot1.data.errors import ReferenceOptionError, SliceError
from albot1.data.model import Frame, Sequence
from albot1.geometry import se2

#: Slack of the view-spacing rule, so ten 0.1 m steps (0.9999999... m in floating point) make 1 m.
SPACING_SLACK = 1e-9


def head(sequence: Sequence, count: int) -> Sequence:
    """The first ``count`` frames (still streamed; the scan count stays known if it was)."""
    if count < 1:
        raise SliceError(f"expected a positive number of scans (a limit or slice stop of at least 1), got {count}")
    known = sequence.known_scan_count
    # islice takes at most sys.maxsize: a larger count (``intel[:99999999999999999999]``) is every scan, not a crash
    return sequence.with_frames(
        lambda frames: itertools.islice(frames, min(count, sys.maxsize)),
        scan_count=None if known is None else min(count, known),
    )


def stride(sequence: Sequence, step: int) -> Sequence:
    """Every ``step``-th frame, renumbered from 0 (the scan count stays known if it was)."""
    if step < 1:
        raise SliceError(f"expected a positive stride (every STEP-th scan, STEP >= 1), got {step}")

    def pick(frames: Iterator[Frame]) -> Iterator[Frame]:
        for i, frame in enumerate(itertools.islice(frames, 0, None, min(step, sys.maxsize))):
            yield replace(frame, index=i)

    known = sequence.known_scan_count
    return sequence.with_frames(pick, scan_count=None if known is None else -(-known // step))


def reference_odometry(sequence: Sequence) -> Sequence:
    """The odometry of every frame replaced by its reference pose (the thesis's perfect-odometry runs).

    A frame without a reference pose is a :class:`ReferenceOptionError`
    naming it: no pose is invented for it.
    """
    name = sequence.name

    def swap(frames: Iterator[Frame]) -> Iterator[Frame]:
        for frame in frames:
            if frame.reference is None:
                raise ReferenceOptionError(
                    f"{name}: odometry=reference needs a reference pose for every scan; scan {frame.index} has none"
                )
            yield replace(frame, odometry=np.array(frame.reference, dtype=float))

    source = sequence.metadata.reference_source or "reference poses"
    metadata = replace(sequence.metadata, odometry_source=f"reference poses as odometry ({source})")
    return sequence.with_frames(swap, metadata=metadata)


def view_spacing(sequence: Sequence, distance_m: float, angle_deg: float) -> Sequence:
    """Keep a frame only once the odometry has moved ``distance_m`` or turned ``angle_deg`` since the last kept one.

    The rule of the thesis's data logger (Experiments 4 and 5: a view every
    10 cm or 1 degree, or every 1 m or 10 degrees): the first frame is kept;
    a later frame is kept when the straight-line distance between its
    odometry position and the last kept one's is at least ``distance_m``, or
    the absolute heading change is at least ``angle_deg`` (both within
    :data:`SPACING_SLACK`). Kept frames are renumbered from 0; their
    odometry, reference and timestamps are unchanged, so a degradation
    applied afterwards acts on the kept views' steps.
    """
    if not (math.isfinite(distance_m) and distance_m > 0 and math.isfinite(angle_deg) and angle_deg > 0):
        raise ReferenceOptionError(
            f"{sequence.name}: views={distance_m:g}:{angle_deg:g}; expected a positive distance (m) and angle (deg)"
        )
    angle = math.radians(angle_deg)

    def keep(frames: Iterator[Frame]) -> Iterator[Frame]:
        last: np.ndarray | None = None
        kept = 0
        for frame in frames:
            odo = frame.odometry
            if last is not None:
                moved = math.hypot(float(odo[0] - last[0]), float(odo[1] - last[1]))
                turned = abs(math.remainder(float(odo[2] - last[2]), 2.0 * math.pi))
                if moved < distance_m - SPACING_SLACK and turned < angle - SPACING_SLACK:
                    continue
            last = np.asarray(odo, dtype=float)
            yield replace(frame, index=kept)
            kept += 1

    extra = {**sequence.metadata.extra, "view_spacing": {"distance_m": distance_m, "angle_deg": angle_deg}}
    return sequence.with_frames(keep, metadata=replace(sequence.metadata, extra=extra))


def sensor_frame(sequence: Sequence) -> Sequence:
    """The sequence as its laser sees it: every pose moved onto the laser, the mounting offset then zero.

    A scan is measured from the laser, which sits at ``metadata.sensor_offset``
    (x, y, yaw) on the robot; the odometry and reference poses are the robot's.
    Composing every pose with the offset gives the laser's own trajectory, in
    which the scans *are* centred, so a method that treats the scan origin as
    its body (every method here) is right without knowing the offset. This is
    the one place the offset is applied for every method; the runner maps the
    method's poses back with :func:`robot_frame` (``docs/datasets.md``, "Sensor
    offsets"). A sequence with a zero offset is returned unchanged.
    """
    offset = np.asarray(sequence.metadata.sensor_offset, dtype=float)
    if not offset.any():
        return sequence

    def move(frames: Iterator[Frame]) -> Iterator[Frame]:
        for frame in frames:
            reference = None if frame.reference is None else se2.compose(frame.reference, offset)
            yield replace(frame, odometry=se2.compose(frame.odometry, offset), reference=reference)

    metadata = replace(
        sequence.metadata,
        sensor_offset=(0.0, 0.0, 0.0),
        extra={**sequence.metadata.extra, "poses_moved_to_sensor": [float(v) for v in offset]},
    )
    return sequence.with_frames(move, metadata=metadata, scan_count=sequence.known_scan_count)


def robot_frame(poses: np.ndarray, sensor_offset: tuple[float, float, float] | np.ndarray) -> np.ndarray:
    """Laser poses ``(N, 3)`` back to robot poses: ``pose * inv(offset)`` (unchanged for a zero offset)."""
    offset = np.asarray(sensor_offset, dtype=float)
    poses = np.asarray(poses, dtype=float)
    if not offset.any() or poses.size == 0:
        return poses
    return se2.compose(poses, se2.inverse(offset))
