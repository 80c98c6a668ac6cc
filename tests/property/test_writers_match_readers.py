"""Every writer refuses what its reader refuses: for arbitrary sequences (good and bad values mixed), a
writer either raises a DataError and leaves nothing behind, or writes a file that its reader loads in full."""

from __future__ import annotations

import math
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.loaders.registry import load, writer_for
from albot1.data.model import Frame, Scan, Sequence

NAMES = {"carmen": "x.clf", "albot-log": "x.albotlog", "ros1": "x.bag", "ros2-sqlite3": "x_db3", "ros2-mcap": "x_mcap"}

ODD = [0.0, -0.0, 1e-7, -1.0, math.nan, math.inf, -math.inf, 1e39, 1e300, 7.0]


def mostly(good: object, odd: list[object], dirty: bool) -> st.SearchStrategy[object]:
    """In a dirty sequence ``good`` nine times in ten, else one of the odd values; in a clean one ``good``.

    Half the sequences are clean, so both directions are exercised: refused writes and written files.
    """
    return st.sampled_from([good] * (9 * len(odd)) + odd) if dirty else st.just(good)


@st.composite
def scans(draw: st.DrawFn, dirty: bool) -> Scan:
    beams = draw(mostly(181, [0, 1, 2, 5, 400], dirty))
    kind = draw(mostly("even", ["descending", "uneven", "wide", "odd-start"], dirty))
    step = {"even": 0.0174, "descending": -0.0174, "uneven": 0.0174, "wide": 0.2, "odd-start": 0.0174}[kind]
    start = draw(st.sampled_from(ODD)) if kind == "odd-start" else -1.5
    angles = start + step * np.arange(beams, dtype=np.float64)
    if kind == "uneven" and beams > 2:
        angles[1] += 0.005
    max_range = draw(mostly(30.0, [0.0, -1.0, math.nan, 1e-7, 1e39], dirty))
    base = draw(mostly("normal", ["zeros", "none", "odd", "one-odd"], dirty))
    ranges = np.linspace(0.5, 20.0, beams)
    if base == "zeros":
        ranges = np.zeros(beams)
    elif base == "none":
        ranges = np.full(beams, math.nan)
    elif base == "odd":
        ranges = np.full(beams, draw(st.sampled_from(ODD)))
    elif base == "one-odd" and beams:
        ranges[draw(st.integers(0, beams - 1))] = draw(st.sampled_from(ODD))
    return Scan(ranges, angles, draw(mostly(0.0, [5e8, -3.0, math.nan, 1e300], dirty)), max_range)


@st.composite
def sequences(draw: st.DrawFn) -> Sequence:
    dirty = draw(st.booleans())
    count = draw(mostly(3, [0, 1, 5], dirty))
    frames = []
    t = 10.0
    for i in range(count):
        scan = draw(scans(dirty))
        t += draw(mostly(0.1, [0.0, -0.5, -5.0], dirty))
        pose = np.array([draw(mostly(1.0, ODD, dirty)), 0.0, draw(mostly(0.5, [3.0, 10.0, -7.0, math.nan], dirty))])
        reference = draw(mostly(None, [np.array([0.0, 2.0, 0.1]), np.array([math.nan, 0.0, 0.0])], dirty))
        frames.append(Frame(i, Scan(scan.ranges, scan.angles, t + scan.timestamp, scan.max_range), pose, reference))
    return Sequence.from_frames("fuzz", frames)


@pytest.mark.slow
@pytest.mark.parametrize("fmt", list(NAMES))
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(seq=sequences())
def test_written_files_load_in_full_or_nothing_is_written(fmt: str, seq: Sequence) -> None:
    folder = Path(tempfile.mkdtemp(prefix="albot1-writer-"))
    try:
        out = folder / NAMES[fmt]
        try:
            writer_for(fmt).write(seq, out)
        except DataError:
            assert list(folder.iterdir()) == [], "a refused write must leave nothing behind"
            return
        loaded = list(load(out).frames())  # must not raise: the reader accepts what the writer wrote
        assert len(loaded) == len(list(seq.frames()))
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@st.composite
def near_max_scans(draw: st.DrawFn, zeros: bool) -> Sequence:
    """One to three scans whose readings crowd the max range: exactly at it, within the CARMEN reader's 5 mm
    no-return margin below it, ordinary, no return (NaN) and, with ``zeros``, 0 m (no return as well)."""
    max_range = draw(st.sampled_from([30.0, 5.6, 80.99, 0.5]))
    reading = st.one_of(
        st.just(max_range),
        st.floats(max_range - 0.006, max_range),
        st.floats(1e-3, max_range),
        st.just(math.nan),
        *([st.just(0.0)] if zeros else []),
    )
    angles = np.linspace(-1.5, 1.5, 7)
    frames = [
        Frame(
            i,
            Scan(np.array(draw(st.lists(reading, min_size=7, max_size=7))), angles, 1.0 + i, max_range),
            np.array([0.1 * i, 0.0, 0.0]),
            None,
        )
        for i in range(draw(st.integers(1, 3)))
    ]
    return Sequence.from_frames("near-max", frames)


@pytest.mark.slow
@pytest.mark.parametrize("fmt", list(NAMES))
# 10 examples: a bag written and read costs about 0.5 s; each example draws 7-21 readings, 2 in 5 of them at or
# within the no-return margin of the max range and 1 in 5 a 0 m reading, so every defect this guards shows in one
@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_round_trips_keep_every_return_and_every_no_return(fmt: str, data: st.DataObject) -> None:
    """A return at (or just below) the max range used to come back from a CARMEN log as no return, and a bag's
    0 m reading as a point at the laser. Written and read back, every return is a return at the same range (to
    the format's precision: 6 decimals, float32) and every no-return (NaN; 0 m in CARMEN and bags, where 0 is
    the "no echo" value) is NaN. The albot log keeps a 0 m point as written, so it gets no zeros here."""
    seq = data.draw(near_max_scans(zeros=fmt != "albot-log"))
    folder = Path(tempfile.mkdtemp(prefix="albot1-roundtrip-"))
    try:
        out = folder / NAMES[fmt]
        writer_for(fmt).write(seq, out)
        for before, after in zip(seq.frames(), load(out).frames(), strict=True):
            returns = np.isfinite(before.scan.ranges) & (before.scan.ranges != 0.0)
            np.testing.assert_array_equal(np.isfinite(after.scan.ranges), returns)
            np.testing.assert_array_equal(np.isnan(after.scan.ranges), ~returns)  # no return reads NaN, not inf
            # the CARMEN writer may declare the max range up to 6 mm higher (a return within the no-return margin);
            # a writer raising it further, or lowering it, would change which readings mean "no echo"
            assert before.scan.max_range - 1e-5 <= after.scan.max_range <= before.scan.max_range + 0.0061
            np.testing.assert_allclose(after.scan.ranges[returns], before.scan.ranges[returns], rtol=1e-6, atol=1e-6)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
