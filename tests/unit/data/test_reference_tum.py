"""A sequence's reference poses as a TUM file: exact round trip, refusals before any file is written."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import UnwritableError, WriteError
from albot1.data.model import Frame, Scan, Sequence
from albot1.data.reference_tum import write_reference_tum
from albot1.data.trajectory import read_trajectory


def _sequence(stamps: list[float], references: list[tuple[float, float, float] | None]) -> Sequence:
    angles = np.array([-0.5, 0.0, 0.5])
    frames = [
        Frame(
            index=i,
            scan=Scan(ranges=np.array([1.0, 2.0, 3.0]), angles=angles, timestamp=t, max_range=10.0),
            odometry=np.zeros(3),
            reference=None if ref is None else np.array(ref, dtype=float),
        )
        for i, (t, ref) in enumerate(zip(stamps, references, strict=True))
    ]
    return Sequence.from_frames("demo", frames)


def test_reference_poses_come_back_from_the_file(tmp_path: Path) -> None:
    poses = [(0.0, 0.0, 0.0), (1.5, -0.25, 0.5), (2.0, 1.0, -3.0)]
    out = tmp_path / "sub" / "gt.tum"
    done = write_reference_tum(_sequence([10.0, 10.5, 11.25], poses), out)
    assert (done.poses, done.retimed, done.output) == (3, 0, out)
    back = read_trajectory(out)
    assert back.format == "tum"
    assert back.timestamps is not None
    np.testing.assert_allclose(back.timestamps, [10.0, 10.5, 11.25], atol=1e-9)
    np.testing.assert_allclose(back.poses[:, :2], np.array(poses)[:, :2], atol=1e-9)
    np.testing.assert_allclose(back.poses[:, 2], [0.0, 0.5, -3.0], atol=1e-8)


def test_a_scan_without_reference_is_refused_and_nothing_is_written(tmp_path: Path) -> None:
    out = tmp_path / "gt.tum"
    with pytest.raises(UnwritableError, match=r"gt.tum: scan 1 \(t = 2.000000 s\) of demo has no reference pose"):
        write_reference_tum(_sequence([1.0, 2.0], [(0.0, 0.0, 0.0), None]), out)
    assert not out.exists()


def test_stamps_that_go_back_are_refused_unless_retimed(tmp_path: Path) -> None:
    refs: list[tuple[float, float, float] | None] = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (2.0, 0.0, 0.0)]
    sequence = _sequence([5.0, 5.0, 4.0], refs)
    with pytest.raises(UnwritableError, match=r"scan 1 of demo is stamped 5.000000 s, not after .* --retime"):
        write_reference_tum(sequence, tmp_path / "a.tum")
    assert not (tmp_path / "a.tum").exists()
    done = write_reference_tum(sequence, tmp_path / "b.tum", retime=True)
    assert done.retimed == 2
    back = read_trajectory(tmp_path / "b.tum")
    assert back.timestamps is not None
    np.testing.assert_allclose(back.timestamps, [5.0, 5.000001, 5.000002], atol=1e-9)


def test_an_existing_output_is_never_overwritten(tmp_path: Path) -> None:
    out = tmp_path / "gt.tum"
    out.write_text("keep\n")
    with pytest.raises(WriteError, match="exists already"):
        write_reference_tum(_sequence([1.0], [(0.0, 0.0, math.pi / 2)]), out)
    assert out.read_text() == "keep\n"
