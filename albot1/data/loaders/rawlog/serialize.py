"""MRPT's binary serialization of the few classes a 2D laser rawlog needs.

A rawlog is a concatenation of serialized objects (optionally gzip-compressed).
Each object is one byte ``0x80 | len(class_name)``, the class name in ASCII,
one byte of class version, the payload, and the end marker ``0x88``;
everything is little endian. The payloads below are those of the class
versions MRPT 2.5 reads (the layout is recorded in ``docs/baselines.md``,
section MRPT; ``rawlog-edit --info`` parses files made with it, which the
integration tests check).

The functions are pure (bytes in, bytes out) so they can be tested exactly
without MRPT installed.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

#: Every serialized object ends with this byte.
END_MARKER = 0x88
#: Seconds from 1601-01-01 (the epoch of ``mrpt::Clock``) to 1970-01-01.
FILETIME_EPOCH_OFFSET_S = 11_644_473_600
#: ``mrpt::Clock`` ticks per second (100 ns ticks).
TICKS_PER_S = 10_000_000

CLASS_POSE2D = "mrpt::poses::CPose2D"
CLASS_POSE3D = "mrpt::poses::CPose3D"
CLASS_RANGE_SCAN = "mrpt::obs::CObservation2DRangeScan"
CLASS_ODOMETRY = "mrpt::obs::CObservationOdometry"
CLASS_MOVEMENT_2D = "mrpt::obs::CActionRobotMovement2D"
CLASS_ACTION_COLLECTION = "mrpt::obs::CActionCollection"
CLASS_SENSORY_FRAME = "mrpt::obs::CSensoryFrame"

#: Class versions written (those MRPT 2.5.8 reads; see the module doc).
VERSIONS = {
    CLASS_POSE2D: 1,
    CLASS_POSE3D: 3,
    CLASS_RANGE_SCAN: 7,
    CLASS_ODOMETRY: 2,
    CLASS_MOVEMENT_2D: 7,
    CLASS_ACTION_COLLECTION: 0,
    CLASS_SENSORY_FRAME: 2,
}


@dataclass(frozen=True)
class GaussianMotionModel:
    """Parameters of MRPT's Gaussian odometry model (``TOptions_GaussianModel``).

    The standard deviation of each translation component is
    ``min_std_xy + a1 * distance + a2 * |turn|`` and that of the heading
    ``min_std_phi + a3 * distance + a4 * |turn|`` (distance in m, turn in rad).
    The defaults are MRPT 2.5's own (``TMotionModelOptions``).
    """

    a1: float = 0.01
    a2: float = math.degrees(0.001)
    a3: float = math.radians(1.0)
    a4: float = 0.05
    min_std_xy: float = 0.01
    min_std_phi: float = math.radians(0.2)


#: MRPT 2.5's defaults of the (unused, but always serialized) Thrun motion model:
#: particle count, then alfa1..alfa4, additional std of x/y and of phi.
THRUN_DEFAULTS = (
    300,
    (0.05, math.radians(4.0), 0.01, math.degrees(0.0001), 0.001, math.radians(0.05)),
)


def mrpt_timestamp(unix_s: float) -> int:
    """``mrpt::Clock`` ticks (100 ns since 1601-01-01) of a Unix time in seconds."""
    if not math.isfinite(unix_s):
        raise ValueError(f"timestamp {unix_s!r} is not finite")
    # Whole seconds and the offset are added as integers and only the (exact) fraction is scaled:
    # scaling 1.1e9 s or adding 1.2e10 s in float64 would round away the last 100 ns ticks.
    whole = math.floor(unix_s)
    ticks = (whole + FILETIME_EPOCH_OFFSET_S) * TICKS_PER_S + round((unix_s - whole) * TICKS_PER_S)
    if not 0 <= ticks < 2**64:
        raise ValueError(f"timestamp {unix_s!r} s is outside the range of mrpt::Clock")
    return ticks


def string(text: str) -> bytes:
    """An MRPT string: uint32 length + bytes."""
    raw = text.encode("ascii")
    return struct.pack("<I", len(raw)) + raw


def serialized(class_name: str, payload: bytes) -> bytes:
    """One serialized object: header, class name, version, payload, end marker."""
    name = class_name.encode("ascii")
    if not 0 < len(name) < 0x80:
        raise ValueError(f"class name {class_name!r} must be 1-127 ASCII characters")
    return bytes([0x80 | len(name)]) + name + bytes([VERSIONS[class_name]]) + payload + bytes([END_MARKER])


def pose2d(x: float, y: float, phi: float) -> bytes:
    """``CPose2D`` v1: x, y, phi as float64."""
    return serialized(CLASS_POSE2D, struct.pack("<3d", x, y, phi))


def pose3d(x: float, y: float, z: float, yaw: float) -> bytes:
    """``CPose3D`` v3 of a pose rotated about z only: x, y, z, then the row-major rotation matrix."""
    c, s = math.cos(yaw), math.sin(yaw)
    rotation = (c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
    return serialized(CLASS_POSE3D, struct.pack("<12d", x, y, z, *rotation))


def range_scan(
    ranges: ArrayLike,
    valid: ArrayLike,
    *,
    aperture_rad: float,
    max_range_m: float,
    sensor_pose: tuple[float, float, float],
    stamp: int,
    label: str = "LASER",
    std_error_m: float = 0.01,
) -> bytes:
    """``CObservation2DRangeScan`` v7 of beams ordered counter-clockwise (``rightToLeft = 1``).

    MRPT places beam ``i`` of ``N`` at ``-aperture/2 + i * aperture / (N - 1)``
    in the sensor frame; ``sensor_pose`` is (x, y, yaw) of the sensor on the
    robot. ``ranges`` of invalid beams are written as given (MRPT ignores them).
    """
    r = np.ascontiguousarray(ranges, dtype="<f4")
    v = np.ascontiguousarray(valid, dtype=np.uint8)
    if r.ndim != 1 or r.shape != v.shape:
        raise ValueError(f"ranges {r.shape} and valid flags {v.shape} must be equal 1-D shapes")
    payload = b"".join(
        (
            struct.pack("<fBf", aperture_rad, 1, max_range_m),
            pose3d(sensor_pose[0], sensor_pose[1], 0.0, sensor_pose[2]),
            struct.pack("<I", len(r)),
            r.tobytes(),
            v.tobytes(),
            struct.pack("<fQf", std_error_m, stamp, 0.0),  # stdError, timestamp, beamAperture
            string(label),
            struct.pack("<dB", 0.0, 0),  # deltaPitch, hasIntensity
        )
    )
    return serialized(CLASS_RANGE_SCAN, payload)


def odometry(pose: ArrayLike, stamp: int, label: str = "ODOMETRY") -> bytes:
    """``CObservationOdometry`` v2: the absolute odometry pose, no encoders, no velocities."""
    x, y, phi = (float(v) for v in np.asarray(pose, dtype=float))
    payload = pose2d(x, y, phi) + string(label) + struct.pack("<QBB", stamp, 0, 0)
    return serialized(CLASS_ODOMETRY, payload)


def robot_movement_2d(increment: ArrayLike, stamp: int, model: GaussianMotionModel) -> bytes:
    """``CActionRobotMovement2D`` v7 from an odometry increment (Gaussian model).

    MRPT rebuilds the pose-change distribution from the raw increment and the
    model parameters when it reads the object.
    """
    dx, dy, dphi = (float(v) for v in np.asarray(increment, dtype=float))
    thrun_count, thrun_params = THRUN_DEFAULTS
    payload = b"".join(
        (
            struct.pack("<I", 0),  # estimationMethod = emOdometry
            pose2d(dx, dy, dphi),
            struct.pack("<I", 0),  # motion model = mmGaussian
            struct.pack("<6f", model.a1, model.a2, model.a3, model.a4, model.min_std_xy, model.min_std_phi),
            struct.pack("<I6f", thrun_count, *thrun_params),
            struct.pack("<BBQ", 0, 0, stamp),  # hasVelocities, hasEncodersInfo, timestamp
        )
    )
    return serialized(CLASS_MOVEMENT_2D, payload)


def action_collection(actions: Iterable[bytes]) -> bytes:
    """``CActionCollection`` v0: uint32 count + the serialized actions."""
    items = list(actions)
    return serialized(CLASS_ACTION_COLLECTION, struct.pack("<I", len(items)) + b"".join(items))


def sensory_frame(observations: Iterable[bytes]) -> bytes:
    """``CSensoryFrame`` v2: uint32 count + the serialized observations."""
    items = list(observations)
    return serialized(CLASS_SENSORY_FRAME, struct.pack("<I", len(items)) + b"".join(items))
