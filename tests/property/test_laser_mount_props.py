"""The laser mount rule as the parsers apply it: a mount is read iff it lies within MAX_MOUNT_M of the base.

An albot log's ``MOUNT x y theta`` line and a CARMEN log's ``robot_frontlaser_offset`` / ``_side_offset``
PARAMs used to be read whatever their size (a mount in millimetres placed every scan 200 m off the robot);
a repeated ``MOUNT`` line with another value used to replace the first without a word.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.errors import ParseError
from albot1.data.open import open_sequence

LIMIT_M = 20.0
METRES = st.floats(-60.0, 60.0, allow_nan=False).filter(lambda v: abs(abs(v) - LIMIT_M) > 1e-9)
HEADER = "ALBOT1-LOG 1\nUNITS length=m angle=rad time=s\nFRAME thesis\n"
BODY = "SENSOR 3 10.0 -1.5707963267948966 1.5707963267948966\nVIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5 nan nan\n"


def opened(name: str, text: str) -> tuple[tuple[float, float, float] | None, str]:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / name
        path.write_text(text)
        try:
            sequence = open_sequence(str(path))
            list(sequence.frames())
            return tuple(float(v) for v in sequence.metadata.sensor_offset), ""  # type: ignore[return-value]
        except ParseError as error:
            return None, str(error)


@settings(max_examples=60, deadline=None)
@given(x=METRES, y=METRES, theta=st.floats(-3.0, 3.0), again=st.sampled_from(["same", "other", "none"]))
def test_albot_log_mount_is_read_iff_within_the_limit(x: float, y: float, theta: float, again: str) -> None:
    mount = f"MOUNT {x!r} {y!r} {theta!r}\n"
    second = {"same": f"NAME r\n{mount}", "other": f"MOUNT {x!r} {y!r} {theta + 1.0!r}\n", "none": ""}[again]
    offset, error = opened("m.albotlog", HEADER + mount + second + BODY)
    if math.hypot(x, y) > LIMIT_M:
        assert offset is None and ":4: MOUNT " in error and f"expected at most {LIMIT_M:g} m" in error
    elif again == "other":
        assert offset is None and ":5: MOUNT " in error and "but line 4 says MOUNT" in error
    else:
        assert offset == (x, y, theta), error


@settings(max_examples=40, deadline=None)
@given(offset=METRES, side=METRES)
def test_carmen_mount_params_are_read_iff_within_the_limit(offset: float, side: float) -> None:
    ranges = " ".join(["2.0"] * 180)
    text = (
        f"PARAM robot_frontlaser_offset {offset!r} nohost 0\nPARAM robot_frontlaser_side_offset {side!r} nohost 0\n"
        f"FLASER 180 {ranges} 0 0 0 0 0 0 1.0 nohost 1.0\nFLASER 180 {ranges} 0 0 0 0 0 0 2.0 nohost 2.0\n"
    )
    got, error = opened("m.clf", text)
    if abs(offset) > LIMIT_M:
        assert got is None and ":1: PARAM robot_frontlaser_offset is " in error
    elif abs(side) > LIMIT_M:
        assert got is None and ":2: PARAM robot_frontlaser_side_offset is " in error
    elif math.hypot(offset, side) > LIMIT_M:  # each part within the limit, the laser not
        assert got is None and "puts the laser" in error and f"expected at most {LIMIT_M:g} m" in error
    else:
        assert got is not None and abs(got[0] - offset) < 1e-12 and abs(got[1] - side) < 1e-12, error
