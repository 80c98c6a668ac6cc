"""The laser's mount (``sensor_offset``) is held to MAX_MOUNT_M by every loader and writer.

A mount is the laser's place on the robot; one written in millimetres (``200`` for 0.2 m), or a 1e300 from a
corrupt file, used to load and place every scan that far off the robot (an albot log's ``MOUNT 1e300 0 0``
made every run fail as "diverged", with a numpy RuntimeWarning on the way).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import DataError, ParseError
from albot1.data.finite import checked
from albot1.data.loaders.albot_log.loader import AlbotLogWriter
from albot1.data.loaders.carmen.writer import CarmenWriter
from albot1.data.loaders.rosbag.writer import Ros1BagWriter
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata
from albot1.data.open import open_sequence

HEADER = "ALBOT1-LOG 1\nUNITS length=m angle=rad time=s\nFRAME thesis\n"
BODY = "SENSOR 3 10.0 -1.5707963267948966 1.5707963267948966\nVIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5 nan nan\n"


def sequence(offset: tuple[float, float, float]) -> Sequence:
    frames = [Frame(i, Scan(np.ones(3), np.array([-0.5, 0.0, 0.5]), float(i), 10.0), np.zeros(3)) for i in range(2)]
    return Sequence.from_frames("m", frames, SequenceMetadata(sensor_offset=offset))


def test_the_rule() -> None:
    from albot1.data.model import MAX_MOUNT_M, mount_problem

    assert mount_problem((0.22, 0.0, math.pi)) is None
    assert mount_problem((MAX_MOUNT_M, 0.0, 0.0)) is None
    assert mount_problem((0.0, -MAX_MOUNT_M, 0.0)) is None
    assert "puts the laser 20.0001 m" in str(mount_problem((20.0001, 0.0, 0.0)))
    assert "puts the laser 25 m" in str(mount_problem((15.0, 20.0, 0.0)))  # the distance, not each part
    assert "is not finite" in str(mount_problem((0.0, 0.0, math.nan)))


@pytest.mark.parametrize("line", ["MOUNT 200 0 0", "MOUNT 1e300 0 0", "MOUNT 0 -21 0.5"])
def test_albot_log_mount_line_is_refused_at_its_line(tmp_path: Path, line: str) -> None:
    path = tmp_path / "far.albotlog"
    path.write_text(HEADER + line + "\n" + BODY)
    with pytest.raises(ParseError, match=r"far\.albotlog:4: MOUNT .*from the robot's base; expected at most 20 m"):
        open_sequence(str(path))


def test_carmen_param_offset_is_refused_at_its_line(tmp_path: Path) -> None:
    ranges = " ".join(["2.0"] * 180)
    path = tmp_path / "mm.clf"
    path.write_text(
        "PARAM robot_frontlaser_offset 200 nohost 0\n"
        f"FLASER 180 {ranges} 0 0 0 0 0 0 1.0 nohost 1.0\nFLASER 180 {ranges} 0 0 0 0 0 0 2.0 nohost 2.0\n"
    )
    with pytest.raises(
        ParseError,
        match=r"mm\.clf:1: PARAM robot_frontlaser_offset is '200', expected an offset in "
        r"metres, at most 20 m",
    ):
        list(open_sequence(str(path)).frames())


def test_any_sequence_is_checked_when_opened() -> None:
    """The safety net of every loader (a ROBOTLASER1 log's mount comes from its lines, a bag's from /tf_static)."""
    with pytest.raises(ParseError, match=r"laser mount .* puts the laser 30 m from the robot's base"):
        checked(sequence((0.0, 30.0, 0.0)))
    assert checked(sequence((0.0, 19.5, 0.0))).metadata.sensor_offset == (0.0, 19.5, 0.0)


@pytest.mark.parametrize(
    ("writer", "name"), [(AlbotLogWriter, "w.albotlog"), (CarmenWriter, "w.clf"), (Ros1BagWriter, "w.bag")]
)
def test_writers_refuse_what_the_readers_refuse(tmp_path: Path, writer: type, name: str) -> None:
    with pytest.raises(DataError, match="puts the laser 200 m from the robot's base"):
        writer().write(sequence((200.0, 0.0, 0.0)), tmp_path / name)
    assert not (tmp_path / name).exists()
    writer().write(sequence((0.2, 0.0, 0.0)), tmp_path / name)
    assert open_sequence(str(tmp_path / name)).metadata.sensor_offset == pytest.approx((0.2, 0.0, 0.0))
