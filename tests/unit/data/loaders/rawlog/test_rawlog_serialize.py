"""MRPT object serialization: exact bytes of each class written for a rawlog."""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest

from albot1.data.loaders.rawlog import serialize as ser


def _split(blob: bytes) -> tuple[str, int, bytes]:
    """(class name, version, payload) of one serialized object, checking header and end marker."""
    n = blob[0] & 0x7F
    assert blob[0] & 0x80
    name = blob[1 : 1 + n].decode("ascii")
    assert blob[-1] == 0x88
    return name, blob[1 + n], blob[2 + n : -1]


def test_timestamps_count_100ns_ticks_since_1601() -> None:
    assert ser.mrpt_timestamp(0.0) == 116_444_736_000_000_000
    assert ser.mrpt_timestamp(1.0000001) == 116_444_736_010_000_001
    # The float nearest 1134864629.895182 is 1134864629.89518189...: its nearest tick.
    assert ser.mrpt_timestamp(1134864629.895182) == 127_793_382_298_951_819
    with pytest.raises(ValueError, match="not finite"):
        ser.mrpt_timestamp(math.nan)
    with pytest.raises(ValueError, match="outside"):
        ser.mrpt_timestamp(-2e10)


def test_pose2d_is_three_float64_in_a_version_1_object() -> None:
    blob = ser.pose2d(1.5, -2.0, 0.25)
    assert blob[0] == 0x80 | len("mrpt::poses::CPose2D")
    assert _split(blob) == ("mrpt::poses::CPose2D", 1, struct.pack("<3d", 1.5, -2.0, 0.25))
    assert len(blob) == 1 + 20 + 1 + 24 + 1


def test_pose3d_holds_the_row_major_rotation_about_z() -> None:
    name, version, payload = _split(ser.pose3d(1.0, 2.0, 0.5, math.pi / 2))
    assert (name, version) == ("mrpt::poses::CPose3D", 3)
    values = struct.unpack("<12d", payload)
    assert values[:3] == (1.0, 2.0, 0.5)
    np.testing.assert_allclose(values[3:], [0, -1, 0, 1, 0, 0, 0, 0, 1], atol=1e-15)


def test_range_scan_fields_in_order() -> None:
    stamp = ser.mrpt_timestamp(10.0)
    blob = ser.range_scan(
        [1.0, 2.5, 80.0], [1, 1, 0], aperture_rad=0.5, max_range_m=80.0, sensor_pose=(0.2, 0.0, 0.1), stamp=stamp
    )
    name, version, p = _split(blob)
    assert (name, version) == ("mrpt::obs::CObservation2DRangeScan", 7)
    aperture, right_to_left, max_range = struct.unpack_from("<fBf", p, 0)
    assert (aperture, right_to_left, max_range) == (np.float32(0.5), 1, 80.0)
    pose = ser.pose3d(0.2, 0.0, 0.0, 0.1)
    assert p[9 : 9 + len(pose)] == pose
    k = 9 + len(pose)
    (n,) = struct.unpack_from("<I", p, k)
    assert n == 3
    ranges = np.frombuffer(p, dtype="<f4", count=3, offset=k + 4)
    assert ranges.tolist() == [1.0, 2.5, 80.0]
    assert list(p[k + 16 : k + 19]) == [1, 1, 0]
    std_error, got_stamp, beam_aperture = struct.unpack_from("<fQf", p, k + 19)
    assert (std_error, got_stamp, beam_aperture) == (np.float32(0.01), stamp, 0.0)
    (label_len,) = struct.unpack_from("<I", p, k + 35)
    assert p[k + 39 : k + 39 + label_len] == b"LASER"
    assert struct.unpack_from("<dB", p, k + 39 + label_len) == (0.0, 0)
    assert len(p) == k + 39 + label_len + 9


def test_range_scan_rejects_mismatched_flags() -> None:
    with pytest.raises(ValueError, match="equal 1-D"):
        ser.range_scan([1.0, 2.0], [1], aperture_rad=1.0, max_range_m=5.0, sensor_pose=(0, 0, 0), stamp=0)


def test_odometry_observation_holds_the_absolute_pose() -> None:
    name, version, p = _split(ser.odometry([1.0, 2.0, 3.0], stamp=42))
    assert (name, version) == ("mrpt::obs::CObservationOdometry", 2)
    pose = ser.pose2d(1.0, 2.0, 3.0)
    assert p.startswith(pose)
    rest = p[len(pose) :]
    assert rest == struct.pack("<I", 8) + b"ODOMETRY" + struct.pack("<QBB", 42, 0, 0)


def test_robot_movement_carries_increment_and_gaussian_model() -> None:
    model = ser.GaussianMotionModel(a1=0.1, a2=0.2, a3=0.3, a4=0.4, min_std_xy=0.05, min_std_phi=0.06)
    name, version, p = _split(ser.robot_movement_2d([0.5, 0.0, 0.1], 7, model))
    assert (name, version) == ("mrpt::obs::CActionRobotMovement2D", 7)
    assert struct.unpack_from("<I", p, 0) == (0,)
    increment = ser.pose2d(0.5, 0.0, 0.1)
    assert p[4 : 4 + len(increment)] == increment
    k = 4 + len(increment)
    assert struct.unpack_from("<I", p, k) == (0,)
    np.testing.assert_allclose(struct.unpack_from("<6f", p, k + 4), [0.1, 0.2, 0.3, 0.4, 0.05, 0.06], rtol=1e-7)
    count, *thrun = struct.unpack_from("<I6f", p, k + 28)
    assert count == 300 and len(thrun) == 6
    assert p[k + 56 :] == struct.pack("<BBQ", 0, 0, 7)


def test_default_motion_model_is_mrpt_2_5s() -> None:
    model = ser.GaussianMotionModel()
    assert (model.a1, model.a4, model.min_std_xy) == (0.01, 0.05, 0.01)
    assert model.a2 == pytest.approx(0.0572958, rel=1e-6)
    assert model.a3 == pytest.approx(math.radians(1.0))
    assert model.min_std_phi == pytest.approx(math.radians(0.2))


def test_containers_count_their_items() -> None:
    obs = ser.odometry([0.0, 0.0, 0.0], 0)
    name, version, p = _split(ser.sensory_frame([obs, obs]))
    assert (name, version) == ("mrpt::obs::CSensoryFrame", 2)
    assert p == struct.pack("<I", 2) + obs + obs
    name, version, p = _split(ser.action_collection([]))
    assert (name, version, p) == ("mrpt::obs::CActionCollection", 0, struct.pack("<I", 0))


def test_class_names_must_fit_the_header_byte() -> None:
    with pytest.raises(ValueError, match="1-127"):
        ser.serialized("x" * 128, b"")
