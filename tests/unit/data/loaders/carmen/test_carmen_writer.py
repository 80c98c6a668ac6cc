"""CarmenWriter -> CarmenLoader round trip: ranges, NaN beams, geometry, max range, both pose sets."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import DataError
from albot1.data.loaders.carmen.loader import CarmenLoader
from albot1.data.loaders.carmen.writer import CarmenWriter
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata


def sequence(with_reference: bool, stamps: list[float]) -> Sequence:
    rng = np.random.default_rng(7)
    angles = np.linspace(-2.0, 2.0, 91)
    frames = []
    for i, t in enumerate(stamps):
        ranges = rng.uniform(0.2, 25.0, size=91)
        ranges[rng.integers(0, 91, size=5)] = np.nan
        odom = np.array([0.1 * i, -0.05 * i, math.remainder(0.3 * i, 2 * math.pi)])
        ref = odom + np.array([0.01, 0.02, 0.003]) if with_reference else None
        frames.append(Frame(i, Scan(ranges, angles, t, 25.5), odom, ref))
    meta = SequenceMetadata(sensor_offset=(0.15, -0.02, 0.01))
    return Sequence.from_frames("synthetic", frames, meta)


@pytest.mark.parametrize("name", ["out.clf", "out.clf.gz", "out.log.bz2"])
@pytest.mark.parametrize("stamps", [[0.1 * k for k in range(20)], [7.0] * 20])
def test_round_trip(tmp_path: Path, name: str, stamps: list[float]) -> None:
    original = sequence(True, stamps)
    CarmenWriter().write(original, tmp_path / name)
    back = CarmenLoader().load(tmp_path / name)
    assert back.metadata.sensor_offset == pytest.approx((0.15, -0.02, 0.01), abs=1e-8)
    pairs = list(zip(original.frames(), back.frames(), strict=True))
    for a, b in pairs:
        np.testing.assert_array_equal(np.isnan(a.scan.ranges), np.isnan(b.scan.ranges))
        np.testing.assert_allclose(a.scan.ranges, b.scan.ranges, atol=5e-7, equal_nan=True)
        np.testing.assert_allclose(a.scan.angles, b.scan.angles, atol=1e-12)
        assert b.scan.max_range == 25.5 and b.scan.timestamp == pytest.approx(a.scan.timestamp, abs=1e-6)
        np.testing.assert_allclose(a.odometry, b.odometry, atol=1e-8)
        np.testing.assert_allclose(a.reference, b.reference, atol=1e-8)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_without_reference_loads_without_reference(tmp_path: Path) -> None:
    CarmenWriter().write(sequence(False, [0.1 * k for k in range(3)]), tmp_path / "o.clf")
    assert CarmenLoader().load(tmp_path / "o.clf").reference is None


def test_uneven_beams_are_rejected_and_nothing_is_left(tmp_path: Path) -> None:
    scan = Scan(np.ones(3), np.array([0.0, 0.1, 0.3]), 0.0, 10.0)
    seq = Sequence.from_frames("u", [Frame(0, scan, np.zeros(3))])
    with pytest.raises(DataError, match="frame 0: beam angles are not evenly spaced"):
        CarmenWriter().write(seq, tmp_path / "u.clf")
    assert list(tmp_path.iterdir()) == []


def frame(i: int, ranges: object, angles: object = None, t: float | None = None, **kw: object) -> Frame:
    a = np.linspace(-1.0, 1.0, 5) if angles is None else np.asarray(angles, dtype=float)
    odom = np.asarray(kw.get("odometry", np.zeros(3)), dtype=float)
    ref = kw.get("reference")
    scan = Scan(np.asarray(ranges, dtype=float), a, float(i) if t is None else t, float(kw.get("max_range", 10.0)))
    return Frame(i, scan, odom, None if ref is None else np.asarray(ref, dtype=float))


@pytest.mark.parametrize(
    ("frames", "message"),
    [
        ([frame(0, np.zeros(5))], r"frame 0: all 5 ranges are 0"),
        ([frame(0, np.ones(5), np.linspace(1.0, -1.0, 5))], r"frame 0: angular_resolution is -0\.5 rad"),
        ([frame(0, np.ones(5), np.arange(5) * 2.0)], r"frame 0: 5 beams 114\.592 deg apart span 458\.366 deg"),
        ([frame(0, [1.0, -1.0, 1.0, 1.0, 1.0])], r"frame 0: range 2 is -1\.0, expected a finite non-negative"),
        ([frame(0, [1.0, np.inf, 1.0, 1.0, 1.0])], r"frame 0: range 2 is inf"),
        ([frame(0, [1.0, 11.0, 1.0, 1.0, 1.0])], r"frame 0: a range of 11\.0 m exceeds max_range 10\.0 m"),
        ([frame(0, np.ones(5), odometry=[0.0, np.nan, 0.0])], r"frame 0: the timestamp and poses must be finite"),
        ([frame(0, np.ones(5), t=5.0), frame(1, np.ones(5), t=3.0)], r"frame 1: scan timestamp 3\.000000 goes back"),
        (
            [frame(0, np.ones(5), reference=[0, 0, 0]), frame(1, np.ones(5))],
            r"frame 0 has a reference pose but frame 1",
        ),
        ([], r"the sequence has no scans"),
    ],
)
def test_the_writer_refuses_what_the_reader_refuses(tmp_path: Path, frames: list[Frame], message: str) -> None:
    with pytest.raises(DataError, match=r"out\.clf: " + message):
        CarmenWriter().write(Sequence.from_frames("bad", frames), tmp_path / "out.clf")
    assert list(tmp_path.iterdir()) == []


def test_stamps_may_jitter_back_within_the_readers_tolerance(tmp_path: Path) -> None:
    frames = [frame(0, np.ones(5), t=5.0), frame(1, np.ones(5), t=4.5), frame(2, np.ones(5), t=6.0)]
    CarmenWriter().write(Sequence.from_frames("jitter", frames), tmp_path / "j.clf")
    assert [f.scan.timestamp for f in CarmenLoader().load(tmp_path / "j.clf").frames()] == [5.0, 4.5, 6.0]


def test_returns_at_the_max_range_stay_returns(tmp_path: Path) -> None:
    """A reading equal to a bag's range_max (or within the reader's 5 mm no-return margin below the max range)
    used to be written as a reading the reader takes for no return. The line now declares a max range raised
    just above the longest return; no-returns (NaN) still come back as no return."""
    ranges = [10.0, 9.997, np.nan, 0.0, 4.0]
    path = tmp_path / "max.clf"
    CarmenWriter().write(Sequence.from_frames("m", [frame(0, ranges, max_range=10.0)]), path)
    scan = next(iter(CarmenLoader().load(path))).scan
    np.testing.assert_array_equal(np.isnan(scan.ranges), [False, False, True, True, False])
    np.testing.assert_allclose(scan.ranges[[0, 1, 4]], [10.0, 9.997, 4.0], atol=1e-6)
    assert 10.0 < scan.max_range <= 10.006
    unchanged = tmp_path / "far.clf"
    CarmenWriter().write(Sequence.from_frames("m", [frame(0, [9.99, 1.0, 2.0, 3.0, 4.0], max_range=10.0)]), unchanged)
    assert next(iter(CarmenLoader().load(unchanged))).scan.max_range == 10.0


def test_a_return_that_prints_as_zero_is_refused(tmp_path: Path) -> None:
    with pytest.raises(DataError, match=r"range 2 of 5 is 1e-07 m, which prints as 0 in the log's 6 decimals"):
        CarmenWriter().write(Sequence.from_frames("z", [frame(0, [1.0, 1e-7, 1.0, 1.0, 1.0])]), tmp_path / "z.clf")
    assert list(tmp_path.iterdir()) == []
