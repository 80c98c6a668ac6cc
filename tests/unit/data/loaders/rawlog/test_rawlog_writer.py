"""Rawlog writer: beam geometry, the two layouts, invalid beams, and `albot1 convert` to .rawlog."""

from __future__ import annotations

import gzip
import io
import math
import struct
from pathlib import Path

import numpy as np
import pytest

from albot1.data.convert import convert, guess_format
from albot1.data.errors import DataError, UnknownFormatError
from albot1.data.loaders.rawlog import serialize as ser
from albot1.data.loaders.rawlog.writer import RawlogWriter, beam_geometry, encode_frame, write_frames
from albot1.data.loaders.registry import loader_for, writer_for
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata

ANGLES_181 = np.radians(np.linspace(-90.0, 90.0, 181))
ANGLES_180 = np.radians(np.arange(-90.0, 90.0, 1.0))  # -90 .. +89 deg, as the Intel and ACES logs


def _frame(i: int, odometry: tuple[float, float, float], angles: np.ndarray = ANGLES_181) -> Frame:
    ranges = np.full(len(angles), 3.0)
    ranges[0] = np.nan  # no return
    ranges[1] = 90.0  # beyond max range
    return Frame(i, Scan(ranges, angles, 100.0 + i, 80.0), np.asarray(odometry, dtype=float))


def _objects(blob: bytes) -> list[tuple[str, bytes]]:
    """Top-level (class name, payload) of a rawlog, walking the sizes the writer uses."""
    out, k = [], 0
    while k < len(blob):
        n = blob[k] & 0x7F
        name = blob[k + 1 : k + 1 + n].decode("ascii")
        start = k + 2 + n
        end = start + _payload_size(name, blob, start)
        assert blob[end] == 0x88, name
        out.append((name, blob[start:end]))
        k = end + 1
    return out


def _object_size(blob: bytes, k: int) -> int:
    n = blob[k] & 0x7F
    name = blob[k + 1 : k + 1 + n].decode("ascii")
    return 2 + n + _payload_size(name, blob, k + 2 + n) + 1


def _payload_size(name: str, blob: bytes, start: int) -> int:
    if name == "mrpt::poses::CPose2D":
        return 24
    if name == "mrpt::poses::CPose3D":
        return 96
    if name in ("mrpt::obs::CActionCollection", "mrpt::obs::CSensoryFrame"):
        (count,) = struct.unpack_from("<I", blob, start)
        k = start + 4
        for _ in range(count):
            k += _object_size(blob, k)
        return k - start
    if name == "mrpt::obs::CObservationOdometry":
        k = start + _object_size(blob, start)
        (label,) = struct.unpack_from("<I", blob, k)
        return k + 4 + label + 10 - start
    if name == "mrpt::obs::CActionRobotMovement2D":
        return 4 + _object_size(blob, start + 4) + 4 + 24 + 28 + 10
    if name == "mrpt::obs::CObservation2DRangeScan":
        k = start + 9
        k += _object_size(blob, k)
        (n,) = struct.unpack_from("<I", blob, k)
        k += 4 + 5 * n + 16
        (label,) = struct.unpack_from("<I", blob, k)
        return k + 4 + label + 9 - start
    raise AssertionError(name)


def test_beam_geometry_centres_the_aperture() -> None:
    g = beam_geometry(ANGLES_181, "x")
    assert g.aperture_rad == pytest.approx(math.pi) and g.centre_rad == pytest.approx(0.0, abs=1e-15)
    g = beam_geometry(ANGLES_180, "x")
    assert math.degrees(g.aperture_rad) == pytest.approx(179.0)
    assert math.degrees(g.centre_rad) == pytest.approx(-0.5)


def test_uneven_or_too_few_beams_are_refused_with_the_frame() -> None:
    with pytest.raises(DataError, match="frame 7: beam angles are not evenly spaced"):
        beam_geometry(np.array([0.0, 0.1, 0.3]), "frame 7")
    with pytest.raises(DataError, match="at least 2"):
        beam_geometry(np.array([0.0]), "frame 0")


def test_observations_layout_is_odometry_then_scan_per_frame() -> None:
    frames = [_frame(0, (1.0, 2.0, 0.0)), _frame(1, (1.5, 2.0, 0.1))]
    out = io.BytesIO()
    stats = write_frames(frames, out, layout="observations")
    objects = _objects(out.getvalue())
    assert [name for name, _ in objects] == [
        "mrpt::obs::CObservationOdometry",
        "mrpt::obs::CObservation2DRangeScan",
    ] * 2
    assert objects[2][1].startswith(ser.pose2d(1.5, 2.0, 0.1))  # absolute odometry
    assert stats.scans == 2 and stats.invalid_beams == 4 and stats.bytes_written == len(out.getvalue())


def test_actions_layout_carries_increments_and_one_scan_per_sensory_frame() -> None:
    frames = [_frame(0, (1.0, 2.0, math.pi / 2)), _frame(1, (1.0, 2.5, math.pi / 2 + 0.1))]
    out = io.BytesIO()
    write_frames(frames, out, layout="actions")
    objects = _objects(out.getvalue())
    assert [name for name, _ in objects] == ["mrpt::obs::CActionCollection", "mrpt::obs::CSensoryFrame"] * 2
    first, second = objects[0][1], objects[2][1]
    movement = 4 + 2 + len("mrpt::obs::CActionRobotMovement2D") + 4  # count, header, name, version, method
    assert first[movement:].startswith(ser.pose2d(0.0, 0.0, 0.0))
    dx, dy, dphi = struct.unpack_from("<3d", second, movement + 2 + len("mrpt::poses::CPose2D"))
    # 0.5 m along the robot's own x axis (it faces +y), then a 0.1 rad turn.
    assert (dx, dy, dphi) == (pytest.approx(0.5), pytest.approx(0.0, abs=1e-12), pytest.approx(0.1))


def test_invalid_beams_are_flagged_and_the_sensor_pose_centres_the_beams() -> None:
    data, invalid = encode_frame(
        _frame(0, (0, 0, 0), ANGLES_180),
        None,
        layout="observations",
        sensor_offset=(0.2, 0.0, 0.0),
        motion_model=ser.GaussianMotionModel(),
    )
    assert invalid == 2
    scan = _objects(data)[1][1]
    aperture, _, max_range = struct.unpack_from("<fBf", scan, 0)
    assert math.degrees(aperture) == pytest.approx(179.0, rel=1e-6) and max_range == 80.0
    pose_len = len(ser.pose3d(0, 0, 0, 0))
    x, y, z, r00, r01, *_ = struct.unpack_from("<12d", scan, 9 + pose_len - 97)
    assert (x, y, z) == (0.2, 0.0, 0.0)
    assert math.degrees(math.atan2(-r01, r00)) == pytest.approx(-0.5)  # the beams' centre angle
    ranges = np.frombuffer(scan, dtype="<f4", count=180, offset=9 + pose_len + 4)
    valid = np.frombuffer(scan, dtype=np.uint8, count=180, offset=9 + pose_len + 4 + 4 * 180)
    assert ranges[:3].tolist() == [80.0, 80.0, 3.0] and valid[:3].tolist() == [0, 0, 1]


def test_bad_odometry_and_layout_are_errors() -> None:
    bad = Frame(3, _frame(0, (0, 0, 0)).scan, np.array([0.0, np.nan, 0.0]))
    with pytest.raises(DataError, match="frame 3: odometry"):
        write_frames([bad], io.BytesIO())
    with pytest.raises(DataError, match="layout 'nope'"):
        RawlogWriter("nope")  # type: ignore[arg-type]


def _sequence(n: int = 3) -> Sequence:
    frames = [_frame(i, (0.5 * i, 0.0, 0.0)) for i in range(n)]
    return Sequence.from_frames("tiny", frames, SequenceMetadata(sensor_offset=(0.1, 0.0, 0.0)))


def test_convert_writes_a_rawlog_chosen_by_its_name_and_gzip_when_asked(tmp_path: Path) -> None:
    assert guess_format("x.rawlog") == "rawlog" and guess_format("x.rawlog.gz") == "rawlog"
    plain, packed = tmp_path / "a.rawlog", tmp_path / "a.rawlog.gz"
    assert convert(_sequence(), plain).scans == 3
    convert(_sequence(), packed)
    assert gzip.decompress(packed.read_bytes()) == plain.read_bytes()
    names = [name for name, _ in _objects(plain.read_bytes())]
    assert names.count("mrpt::obs::CSensoryFrame") == 3
    scan = _objects(plain.read_bytes())[1][1]
    (count,) = struct.unpack_from("<I", scan, 0)
    assert count == 1
    # The metadata's sensor offset is the scan's sensor pose.
    assert ser.pose3d(0.1, 0.0, 0.0, 0.0) in scan


def test_rawlog_is_write_only_in_the_registry(tmp_path: Path) -> None:
    assert isinstance(writer_for("rawlog"), RawlogWriter)
    with pytest.raises(UnknownFormatError, match="can be written but not read"):
        loader_for(tmp_path / "x.rawlog", "rawlog")
    with pytest.raises(UnknownFormatError, match="rawlog"):
        writer_for("nope")


WRITE_ONLY = (
    "albot1 writes rawlogs only as input for MRPT's applications and cannot read them (rawlog is write-only); "
    "give the log it was converted from, or read it with MRPT's own tools"
)


@pytest.mark.parametrize("name", ["back.rawlog", "back.rawlog.gz", "renamed.bin"])
def test_reading_a_rawlog_back_says_it_is_write_only(tmp_path: Path, name: str) -> None:
    """By its name, or by MRPT's serialization header under any name (not "binary data of no known format")."""
    written = tmp_path / ("back.rawlog.gz" if name.endswith(".gz") else "back.rawlog")
    RawlogWriter().write(Sequence.from_frames("r", [_frame(0, (0.0, 0.0, 0.0))]), written)
    path = written if name != "renamed.bin" else written.rename(tmp_path / name)
    with pytest.raises(UnknownFormatError) as info:
        loader_for(path)
    assert str(info.value) == f"{path}: an MRPT rawlog; {WRITE_ONLY}"
    with pytest.raises(UnknownFormatError) as info:
        loader_for(path, "rawlog")
    assert str(info.value) == f"format 'rawlog' can be written but not read; {WRITE_ONLY}"


def test_other_binary_data_is_not_called_a_rawlog(tmp_path: Path) -> None:
    path = tmp_path / "x.bin"
    path.write_bytes(bytes([0x86]) + b"mrpt::" + bytes(range(200)))  # a header too short for a class name
    with pytest.raises(UnknownFormatError, match=r"binary data of no known format"):
        loader_for(path)


def test_an_empty_sequence_leaves_no_file(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="no scans"):
        RawlogWriter().write(Sequence.from_frames("empty", []), tmp_path / "e.rawlog")
    assert not list(tmp_path.iterdir())
