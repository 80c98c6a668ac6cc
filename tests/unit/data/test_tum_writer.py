"""write_tum: one format of the whole file, the bytes numpy.savetxt wrote (session 26).

A run folder's ``trajectory.tum``, ``odometry.tum`` and ``reference.tum`` were ``numpy.savetxt(fmt="%.9f")``
of eight columns; the writer now formats the five columns that vary in one ``%`` and spells the three zero
columns out. These tests hold it to savetxt's bytes where a shortcut could differ: negative zeros (a yaw of
-0.0 has a quaternion qz of -0.0), values that round to zero at 9 decimals from below, large stamps, headings
at +-pi, and no pose at all.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from albot1.data.trajectory import write_tum


def _savetxt(timestamps: np.ndarray, poses: np.ndarray) -> str:
    """The file as numpy.savetxt wrote it until session 26."""
    half = poses[:, 2] / 2.0
    zeros = np.zeros(len(poses))
    rows = np.column_stack([timestamps, poses[:, 0], poses[:, 1], zeros, zeros, zeros, np.sin(half), np.cos(half)])
    buffer = io.StringIO()
    np.savetxt(buffer, rows, fmt="%.9f", header="timestamp x y z qx qy qz qw", comments="# ")
    return buffer.getvalue()


def _awkward() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(26)
    stamps = np.concatenate([[0.0, 1e-10, 1.5e9, 1_234_567_890.123456789], 1e9 + np.cumsum(rng.random(300))])
    poses = np.concatenate(
        [
            [[-0.0, 0.0, -0.0], [-4e-10, 4e-10, -4e-10], [1e6, -1e6, math.pi], [0.5, -0.5, -math.pi]],
            np.cumsum(rng.normal(0.0, 3.0, size=(300, 3)), axis=0),
        ]
    )
    return stamps, poses


def test_the_file_is_the_one_savetxt_wrote(tmp_path: Path) -> None:
    stamps, poses = _awkward()
    write_tum(tmp_path / "a.tum", stamps, poses)
    assert (tmp_path / "a.tum").read_bytes() == _savetxt(stamps, poses).encode("latin-1")
    assert "-0.000000000" in (tmp_path / "a.tum").read_text()  # the negative zeros kept their sign
    buffer = io.StringIO()
    write_tum(buffer, stamps, poses)
    assert buffer.getvalue() == _savetxt(stamps, poses)
    empty = io.StringIO()
    write_tum(empty, np.empty(0), np.empty((0, 3)))
    assert empty.getvalue() == _savetxt(np.empty(0), np.empty((0, 3))) == "# timestamp x y z qx qy qz qw\n"


def test_a_file_is_written_at_once_not_a_line_at_a_time() -> None:
    stamps, poses = _awkward()

    class Counting(io.StringIO):
        writes = 0

        def write(self, text: str) -> int:
            Counting.writes += 1
            return super().write(text)

    handle = Counting()
    write_tum(handle, stamps, poses)
    assert handle.getvalue() == _savetxt(stamps, poses)
    assert Counting.writes == 1  # numpy.savetxt: a write per line and one for the header (305)
