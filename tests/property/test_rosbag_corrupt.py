"""Corrupted bags (flipped bytes, truncation): the loaders raise only DataError, never a rosbags traceback."""

from __future__ import annotations

import functools
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.loaders.rosbag.loader import Ros1BagLoader, Ros2BagLoader
from albot1.data.loaders.rosbag.writer import Ros1BagWriter, Ros2McapWriter, Ros2Sqlite3Writer
from albot1.data.model import Frame, Scan, Sequence

ANGLES = np.deg2rad(np.arange(-90.0, 90.0, 10.0))


#: The bag kinds written by :func:`_bags` (a literal, so that collecting this module writes no bag).
KINDS = ("mcap", "ros1", "sqlite3")


@functools.cache
def _bags() -> dict[str, tuple[bytes, str]]:
    """One small valid bag per kind (bytes, metadata), written once per process when the test first runs."""
    frames = [
        Frame(
            i,
            Scan(np.full(18, 2.0 + 0.1 * i), ANGLES, 1.0 + 0.1 * i, 30.0),
            np.array([0.1 * i, 0.0, 0.0]),
            np.array([0.0, 0.1 * i, 0.0]),
        )
        for i in range(15)
    ]
    seq = Sequence.from_frames("fuzz", frames)
    out: dict[str, tuple[bytes, str]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        Ros1BagWriter().write(seq, root / "a.bag")
        Ros2McapWriter().write(seq, root / "m")
        Ros2Sqlite3Writer().write(seq, root / "s")
        out["ros1"] = ((root / "a.bag").read_bytes(), "")
        out["mcap"] = ((root / "m" / "m.mcap").read_bytes(), (root / "m" / "metadata.yaml").read_text())
        out["sqlite3"] = ((root / "s" / "s.db3").read_bytes(), (root / "s" / "metadata.yaml").read_text())
    return out


EDITS = st.lists(
    st.tuples(st.sampled_from(["flip", "truncate"]), st.floats(0.0, 1.0), st.integers(0, 255)), min_size=1, max_size=4
)


@pytest.mark.slow
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(kind=st.sampled_from(KINDS), edits=EDITS)
def test_corrupted_bags_raise_only_data_errors(tmp_path: Path, kind: str, edits: list[tuple[str, float, int]]) -> None:
    bags = _bags()
    assert sorted(bags) == list(KINDS)
    data, metadata = bags[kind]
    raw = bytearray(data)
    for action, where, value in edits:
        if not raw:
            break
        at = min(int(where * len(raw)), len(raw) - 1)
        if action == "flip":
            raw[at] = value
        else:
            del raw[at:]
    target = tmp_path / kind
    shutil.rmtree(target, ignore_errors=True)
    if kind == "ros1":
        target.mkdir()
        path = target / "a.bag"
        path.write_bytes(bytes(raw))
        loader: Ros1BagLoader | Ros2BagLoader = Ros1BagLoader()
    else:
        target.mkdir()
        name = "m.mcap" if kind == "mcap" else "s.db3"
        (target / name).write_bytes(bytes(raw))
        (target / "metadata.yaml").write_text(metadata)
        path, loader = target, Ros2BagLoader()
    try:
        for frame in loader.load(path).frames():
            assert frame.scan.beams > 0
    except DataError:
        pass
