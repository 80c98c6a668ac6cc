"""TUM quaternions: the heading of an upright pose is read; a pose tilted past MAX_TILT_DEG is refused at its line.

A planar trajectory whose yaw-only quaternions were written w first (``t x y z qw qx qy qz``, Eigen's coefficient
order) used to read as a roll of up to 180 deg whose yaw is 0 at every pose: positions scored as before, every
rotation metric (ATE rotation, RPE rotation, bearing) silently against a heading of 0.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.errors import ParseError
from albot1.data.trajectory import read_tum

HEADING = st.floats(-math.pi, math.pi, allow_nan=False)
UPRIGHT = math.radians(40.0)  # heading h written w first tilts the pose 180 - |h| deg: upright beyond 140 deg
TILTED = math.radians(130.0)


def zyx_quaternion(yaw: float, pitch: float, roll: float) -> tuple[float, float, float, float]:
    """``(qx, qy, qz, qw)`` of the rotation yaw about z, then pitch about y, then roll about x."""
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def read(lines: list[str]) -> tuple[list[float], int | None]:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "t.tum"
        path.write_text("# t x y z qx qy qz qw\n" + "\n".join(lines) + "\n")
        try:
            return [float(v) for v in read_tum(path)[1][:, 2]], None
        except ParseError as error:
            assert "tilts the pose" in str(error) and "TUM's order is qx qy qz qw" in str(error)
            return [], error.line


@settings(max_examples=80, deadline=None)
@given(
    poses=st.lists(
        st.tuples(HEADING, st.floats(-0.5, 0.5), st.floats(-0.5, 0.5)),  # roll, pitch within 29 deg: tilt < 41 deg
        min_size=1,
        max_size=12,
    )
)
def test_an_upright_pose_reads_as_its_heading(poses: list[tuple[float, float, float]]) -> None:
    lines = [f"{i} 1.0 2.0 0.0 " + " ".join(repr(q) for q in zyx_quaternion(*p)) for i, p in enumerate(poses)]
    headings, line = read(lines)
    assert line is None
    for got, (yaw, _, _) in zip(headings, poses, strict=True):
        assert abs(math.remainder(got - yaw, 2 * math.pi)) < 1e-9


@settings(max_examples=80, deadline=None)
@given(
    upright=st.lists(HEADING.filter(lambda h: abs(h) >= math.pi - UPRIGHT), max_size=8),
    tilted=st.floats(-TILTED, TILTED),
    after=st.lists(HEADING, max_size=4),
)
def test_w_first_quaternions_are_refused_at_the_first_pose_they_tilt(
    upright: list[float], tilted: float, after: list[float]
) -> None:
    """Written w first, a heading h is a pose tilted 180 - |h| deg: read (wrongly) when it stays under the
    limit (|h| of 135 deg or more: a trajectory that only ever heads that way cannot be told apart), refused
    at the first pose of any other heading, which every trajectory starting at the origin's heading 0 has."""
    headings = [*upright, tilted, *after]
    lines = [f"{i} 0.0 0.0 0.0 {math.cos(h / 2)!r} 0.0 0.0 {math.sin(h / 2)!r}" for i, h in enumerate(headings)]
    _, line = read(lines)
    assert line == len(upright) + 2  # the header comment is line 1


def test_the_limit() -> None:
    half = math.radians(44.99) / 2
    assert read([f"0 0 0 0 {math.sin(half)!r} 0 0 {math.cos(half)!r}"])[1] is None  # roll 44.99 deg
    half = math.radians(45.01) / 2
    assert read([f"0 0 0 0 0 {math.sin(half)!r} 0 {math.cos(half)!r}"])[1] == 2  # pitch 45.01 deg
    assert read(["0 0 0 0 0 0 0 1", "1 0 0 0 1 0 0 0"])[1] == 3  # qx = 1: upside down
