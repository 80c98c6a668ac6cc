"""Pure conversions between ROS message fields and the data model (no I/O).

Kept apart from the bag readers and writers so the maths (LaserScan beam
geometry, quaternion yaw, odometry interpolation without extrapolation) can
be unit-tested exactly, without ``rosbags`` or a file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from albot1.geometry import se2

FloatArray = NDArray[np.float64]

#: Beam angles that differ from ``angle_min + i * angle_increment`` by more
#: than this cannot be written as a LaserScan (which only knows even spacing).
ANGLE_SPACING_TOLERANCE = 1e-6


def stamp_seconds(sec: int, nanosec: int) -> float:
    """A ROS ``Time`` (``sec``, ``nanosec``) as float seconds."""
    return float(sec) + float(nanosec) * 1e-9


def seconds_to_ns(seconds: float) -> int:
    """Float seconds -> integer nanoseconds (the bag's clock); rounds to the nearest ns."""
    return int(round(seconds * 1e9))


def split_ns(ns: int) -> tuple[int, int]:
    """Nanoseconds -> ROS ``(sec, nanosec)`` with ``0 <= nanosec < 1e9``."""
    return ns // 1_000_000_000, ns % 1_000_000_000


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """The heading (rotation about z) of a quaternion, in ``(-pi, pi]``.

    Roll and pitch are ignored: a 2D robot's odometry quaternion is a pure
    yaw, and a tilted one would still be projected sensibly onto the plane.
    """
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quaternion_from_yaw(theta: float) -> tuple[float, float, float, float]:
    """``(x, y, z, w)`` of a rotation by ``theta`` about z."""
    return 0.0, 0.0, math.sin(theta / 2.0), math.cos(theta / 2.0)


def scan_arrays(
    ranges: ArrayLike, angle_min: float, angle_increment: float, range_min: float, range_max: float
) -> tuple[FloatArray, FloatArray]:
    """``(ranges, angles)`` of a LaserScan in the data model's conventions.

    Readings outside ``[range_min, range_max]``, inf and NaN all mean "no
    usable return" (REP-117) and become NaN. Angles are
    ``angle_min + i * angle_increment`` computed in float64 from the
    message's float32 fields. A negative increment (a clockwise scanner, or
    one mounted upside down) is reversed so angles ascend as the model
    requires; ranges are reversed with them.
    """
    r = np.asarray(ranges, dtype=np.float64).copy()
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(r) | (r < float(range_min)) | (r > float(range_max))
    r[bad] = np.nan
    angles = float(angle_min) + np.arange(r.shape[0], dtype=np.float64) * float(angle_increment)
    if angle_increment < 0:
        return r[::-1].copy(), angles[::-1].copy()
    return r, angles


def even_spacing(angles: FloatArray, tolerance: float = ANGLE_SPACING_TOLERANCE) -> tuple[float, float] | None:
    """``(angle_min, angle_increment)`` if the beams are evenly spaced (within ``tolerance`` rad), else None."""
    n = angles.shape[0]
    if n == 0:
        return None
    first = float(angles[0])
    step = float(angles[-1] - angles[0]) / (n - 1) if n > 1 else 0.0
    rebuilt = first + np.arange(n, dtype=np.float64) * step
    if float(np.max(np.abs(rebuilt - angles))) > tolerance:
        return None
    return first, step


@dataclass(frozen=True)
class PoseTrack:
    """A time-stamped SE(2) trajectory that can be sampled *between* its stamps.

    Headings are unwrapped once at construction so that each query is a
    binary search plus a linear blend (``se2.interpolate`` unwraps on every
    call, which would make per-scan queries O(N)). Queries outside
    ``[times[0], times[-1]]`` return None: the caller decides (error or drop),
    never a silent extrapolation.
    """

    times: FloatArray
    poses: FloatArray
    _unwrapped: FloatArray

    @classmethod
    def build(cls, times: ArrayLike, poses: ArrayLike) -> PoseTrack:
        t = np.asarray(times, dtype=np.float64)
        p = se2.as_poses(poses).reshape(-1, 3)
        if t.shape[0] != p.shape[0] or t.shape[0] == 0:
            raise ValueError(
                f"expected one pose per stamp and at least one, got {t.shape[0]} stamps, {p.shape[0]} poses"
            )
        order = np.argsort(t, kind="stable")
        t, p = t[order], p[order]
        unwrapped = p.copy()
        unwrapped[:, 2] = np.unwrap(p[:, 2])
        return cls(t, p, unwrapped)

    @property
    def start(self) -> float:
        return float(self.times[0])

    @property
    def end(self) -> float:
        return float(self.times[-1])

    def __len__(self) -> int:
        return int(self.times.shape[0])

    def at(self, t: float) -> FloatArray | None:
        """The pose at time ``t`` (exactly a stored pose at a stored stamp), or None outside the span."""
        if not self.start <= t <= self.end:
            return None
        i = int(np.searchsorted(self.times, t, side="left"))
        if self.times[i] == t:
            return self.poses[i].copy()
        t0, t1 = self.times[i - 1], self.times[i]
        f = (t - t0) / (t1 - t0)
        blended = self._unwrapped[i - 1] + f * (self._unwrapped[i] - self._unwrapped[i - 1])
        blended[2] = float(se2.wrap(blended[2]))
        return blended
