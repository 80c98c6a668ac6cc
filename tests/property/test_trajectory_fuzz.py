"""Trajectory readers under arbitrary text: a pose list or the project's DataError, nothing else."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.trajectory import read_kitti, read_tum, write_tum

TOKENS = st.sampled_from(["0", "1", "-2.5", "1e3", "nan", "inf", "x", "#", "", "0.0001", "1,5", "--1"])
LINES = st.lists(st.lists(TOKENS, min_size=0, max_size=14).map(" ".join), max_size=8).map("\n".join)


@settings(max_examples=150, deadline=None)
@given(text=LINES)
def test_tum_and_kitti_readers_return_poses_or_a_data_error(text: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "t.txt"
        path.write_text(text)
        for reader, columns in ((read_tum, 8), (read_kitti, 12)):
            try:
                out = reader(path)
            except DataError:
                continue
            poses = out[1] if isinstance(out, tuple) else out
            assert poses.ndim == 2 and poses.shape[1] == 3 and np.isfinite(poses).all()
            assert columns in (8, 12)


@settings(max_examples=60, deadline=None)
@given(
    poses=st.lists(
        st.tuples(
            st.floats(-1e4, 1e4, allow_nan=False),
            st.floats(-1e4, 1e4, allow_nan=False),
            st.floats(-3.14159, 3.14159, allow_nan=False),
        ),
        min_size=1,
        max_size=20,
    )
)
def test_tum_written_by_us_reads_back_within_the_nine_decimals(poses: list[tuple[float, float, float]]) -> None:
    array = np.asarray(poses, dtype=float)
    stamps = np.arange(len(array), dtype=float) * 0.1
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "t.tum"
        write_tum(path, stamps, array)
        _, back = read_tum(path)
    assert np.abs(back[:, :2] - array[:, :2]).max() <= 1e-9
    wrapped = np.angle(np.exp(1j * (back[:, 2] - array[:, 2])))
    assert np.abs(wrapped).max() < 1e-7
