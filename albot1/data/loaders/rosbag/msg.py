"""Pure conversions between ROS message fields and the data model (no I/O).

Kept apart from the bag readers and writers so the maths (LaserScan beam
geometry, quaternion yaw, odometry interpolation without extrapolation) can
be unit-tested exactly, without ``rosbags`` or a file. The ``*_problem``
functions are the one statement of which field values the reader accepts;
the writer checks what it is about to write with the same functions, so it
never writes a bag the reader refuses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from albot1.data.loaders.beams import seam_repeat
from albot1.data.model import MAX_COORDINATE_M
from albot1.geometry import se2
from albot1.geometry.types import FloatArray

#: How far ``len(ranges)`` may be from the beam count that ``angle_min``, ``angle_max`` and
#: ``angle_increment`` describe. One beam: drivers disagree on whether ``angle_max`` is the last
#: beam or one increment past it (pointcloud_to_laserscan, several 360-degree scanners), and the
#: loader places beams by ``angle_min + i * angle_increment`` either way. The 0.01 absorbs float32.
BEAM_COUNT_SLACK = 1.01
#: Quaternions whose norm is further than this from 1 are refused (a zero quaternion is no rotation);
#: closer ones are normalised before the yaw is taken.
QUATERNION_NORM_TOLERANCE = 0.1
FULL_TURN = 2 * math.pi


def stamp_seconds(sec: int, nanosec: int) -> float:
    """A ROS ``Time`` (``sec``, ``nanosec``) as float seconds."""
    return float(sec) + float(nanosec) * 1e-9


def seconds_to_ns(seconds: float) -> int:
    """Float seconds -> integer nanoseconds (the bag's clock); rounds to the nearest ns.

    Whole seconds and the fraction are converted apart: ``seconds * 1e9`` of a
    Unix time (1.7e18 ns) is a float 256 ns apart from its neighbours, so
    1700000000.75 s became 1700000000.750000128 s in the bag and read back as
    another float; split, it is stored and read back exactly.
    """
    whole = math.floor(seconds)
    return int(whole) * 1_000_000_000 + round((seconds - whole) * 1e9)


def split_ns(ns: int) -> tuple[int, int]:
    """Nanoseconds -> ROS ``(sec, nanosec)`` with ``0 <= nanosec < 1e9``."""
    return ns // 1_000_000_000, ns % 1_000_000_000


def ns_text(ns: int) -> str:
    """Integer nanoseconds as the exact decimal seconds a bag stores (``1200000000`` -> ``"1.200000000"``).

    Said from the integer, not from float seconds, so a message shows the
    stamps the writer compared, without float noise (``1.2000000000000002``).
    """
    sec, nanosec = split_ns(ns)
    return f"{sec}.{nanosec:09d}"


def quaternion_problem(x: float, y: float, z: float, w: float) -> str | None:
    """Why ``(x, y, z, w)`` is not a rotation: non-finite, or a norm far from 1 (e.g. all zeros)."""
    norm = math.sqrt(x * x + y * y + z * z + w * w) if all(map(math.isfinite, (x, y, z, w))) else math.nan
    if math.isfinite(norm) and abs(norm - 1.0) <= QUATERNION_NORM_TOLERANCE:
        return None
    return (
        f"orientation quaternion (x, y, z, w) = ({x!r}, {y!r}, {z!r}, {w!r}) has norm {norm:.6g}, expected a "
        f"unit quaternion (norm 1 +/- {QUATERNION_NORM_TOLERANCE}; all zeros is no rotation, not yaw 0)"
    )


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """The heading (rotation about z) of a quaternion, in ``(-pi, pi]``.

    Roll and pitch are ignored: a 2D robot's odometry quaternion is a pure
    yaw, and a tilted one would still be projected sensibly onto the plane.
    A quaternion that is not quite unit is normalised first (the formula
    assumes norm 1); callers refuse far-off ones with :func:`quaternion_problem`.
    """
    n2 = x * x + y * y + z * z + w * w
    if abs(n2 - 1.0) > 1e-9 and n2 > 0:
        scale = 1.0 / math.sqrt(n2)
        x, y, z, w = x * scale, y * scale, z * scale, w * scale
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def pose_problem(pose: ArrayLike) -> str | None:
    """A planar pose ``(x, y, theta)`` must be finite."""
    values = np.asarray(pose, dtype=np.float64)
    if values.shape == (3,) and bool(np.isfinite(values).all()):
        return None
    return f"pose {values.tolist()} is not three finite numbers (x, y, theta)"


def laserscan_problem(
    beams: int, angle_min: float, angle_max: float, angle_increment: float, range_min: float, range_max: float
) -> str | None:
    """Why LaserScan fields cannot describe a scan of ``beams`` ranges (None if they can).

    Finite fields; at least one range; ``0 <= range_min < range_max``; a
    non-zero increment when there are several beams, spanning at most a full
    turn; and ``beams`` agreeing with ``(angle_max - angle_min) / angle_increment + 1``
    to within :data:`BEAM_COUNT_SLACK`.
    """
    fields = (angle_min, angle_max, angle_increment, range_min, range_max)
    shown = (
        f"angle_min {angle_min!r}, angle_max {angle_max!r}, angle_increment {angle_increment!r} rad, "
        f"range_min {range_min!r}, range_max {range_max!r} m"
    )
    if not all(map(math.isfinite, fields)):
        return f"{shown}: expected finite numbers"
    if beams < 1:
        return "no ranges, expected at least one beam"
    if not 0 <= range_min < range_max:
        return f"range_min {range_min!r} m and range_max {range_max!r} m, expected 0 <= range_min < range_max"
    if beams == 1:
        return None
    if angle_increment == 0:
        return f"{beams} ranges all at angle {angle_min!r} (angle_increment 0), expected a non-zero angle_increment"
    if (beams - 1) * abs(angle_increment) > FULL_TURN + 1e-6:
        return (
            f"{beams} ranges {angle_increment!r} rad apart span {math.degrees((beams - 1) * abs(angle_increment)):.6g} "
            f"deg, expected at most a full turn"
        )
    described = (angle_max - angle_min) / angle_increment + 1.0
    if abs(beams - described) > BEAM_COUNT_SLACK:
        return (
            f"{beams} ranges, but {shown[: shown.index(', range_min')]} describe {described:.6g} beams; expected "
            f"the count to agree with the angles (to within one beam)"
        )
    return None


def reading_problem(ranges: ArrayLike, range_min: float, range_max: float) -> str | None:
    """A reading the scan keeps (within ``[range_min, range_max]``) beyond :data:`MAX_COORDINATE_M`, or None.

    A ``range_max`` of float32's largest value lets any reading through; one of
    1e30 m is no measurement, and its point would overflow the maps' grid
    arithmetic far from the message that holds it. Beams are counted in the
    message's order, from 1.
    """
    r = np.asarray(ranges, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        far = (r > MAX_COORDINATE_M) & (r >= range_min) & (r <= range_max)
    if not far.any():
        return None
    k = int(np.argmax(far))
    return (
        f"range {k + 1} of {r.shape[0]} is {float(r[k]):.6g} m (range_max {range_max:.6g} m), expected at most "
        f"{MAX_COORDINATE_M:g} m: no laser measures farther (a reading beyond range_max is no return)"
    )


def quaternion_from_yaw(theta: float) -> tuple[float, float, float, float]:
    """``(x, y, z, w)`` of a rotation by ``theta`` about z."""
    return 0.0, 0.0, math.sin(theta / 2.0), math.cos(theta / 2.0)


def scan_arrays(
    ranges: ArrayLike,
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    *,
    mirrored: bool = False,
) -> tuple[FloatArray, FloatArray]:
    """``(ranges, angles)`` of a LaserScan in the data model's conventions.

    Readings outside ``[range_min, range_max]``, inf and NaN all mean "no
    usable return" (REP-117) and become NaN; so does a reading of exactly 0
    m, which a driver writes for "no echo" (a return at the laser's own window
    is impossible) and which ``range_min = 0`` (as ``albot1 convert`` writes,
    and many drivers do) used to keep as a point at the laser. Angles are
    ``angle_min + i * angle_increment`` computed in float64 from the
    message's float32 fields. A 360-degree scan whose last beam repeats the
    first's direction (``angle_max = angle_min + 2 pi``,
    :func:`~albot1.data.loaders.beams.seam_repeat`) loses that last beam, so
    the caller sees fewer ranges than the message holds and says so. A
    negative increment (a clockwise scanner, or one mounted upside down) is
    reversed so angles ascend as the model requires; ranges are reversed with
    them. ``mirrored``: the laser is mounted upside down
    (:class:`~albot1.data.loaders.rosbag.mounting.Mounting`), so beam ``i``
    lies at ``-(angle_min + i * angle_increment)`` in the base's plane: the
    angles are negated, then ordered as above.
    """
    r = np.asarray(ranges, dtype=np.float64).copy()
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(r) | (r < float(range_min)) | (r > float(range_max)) | (r == 0.0)
    r[bad] = np.nan
    if mirrored:
        angle_min, angle_increment = -angle_min, -angle_increment
    angles = float(angle_min) + np.arange(r.shape[0], dtype=np.float64) * float(angle_increment)
    if seam_repeat(angles):
        r, angles = r[:-1], angles[:-1]
    if angle_increment < 0:
        return r[::-1].copy(), angles[::-1].copy()
    return r, angles


@dataclass(frozen=True)
class PoseTrack:
    """A time-stamped SE(2) trajectory that can be sampled *between* its stamps.

    Headings are unwrapped once at construction (``se2.unwrap_headings``), so
    that each query is a binary search plus ``se2.interpolate_unwrapped``, the
    one interpolation of the package (``se2.interpolate`` unwraps on every
    call, which would make per-scan queries O(N)). A query at a stored stamp
    returns the stored pose as is. Queries outside ``[times[0], times[-1]]``
    return None: the caller decides (error or drop), never a silent
    extrapolation.
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
        return cls(t, p, se2.unwrap_headings(p))

    @property
    def start(self) -> float:
        return float(self.times[0])

    @property
    def end(self) -> float:
        return float(self.times[-1])

    def __len__(self) -> int:
        return int(self.times.shape[0])

    def bracket(self, t: float) -> tuple[float, float]:
        """The stamps of the two samples a pose at ``t`` (inside the span) is interpolated between;
        ``(t, t)`` at a stored stamp, where nothing is interpolated."""
        i = int(np.searchsorted(self.times, t, side="left"))
        if i < len(self.times) and self.times[i] == t:
            return t, t
        return float(self.times[max(i - 1, 0)]), float(self.times[min(i, len(self.times) - 1)])

    def at(self, t: float) -> FloatArray | None:
        """The pose at time ``t`` (exactly a stored pose at a stored stamp), or None outside the span."""
        if not self.start <= t <= self.end:
            return None
        i = int(np.searchsorted(self.times, t, side="left"))
        if self.times[i] == t:
            stored: FloatArray = self.poses[i].copy()
            return stored
        bracket = slice(i - 1, i + 1)
        blended: FloatArray = se2.interpolate_unwrapped(self.times[bracket], self._unwrapped[bracket], np.array([t]))[0]
        return blended
