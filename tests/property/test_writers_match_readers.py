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
