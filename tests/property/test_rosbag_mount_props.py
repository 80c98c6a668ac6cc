"""Property: any planar laser mount written to /tf_static reads back as the same sensor offset, in any bag format."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.loaders.rosbag.loader import Ros1BagLoader, Ros2BagLoader
from albot1.data.loaders.rosbag.writer import Ros1BagWriter, Ros2McapWriter
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata
from albot1.geometry import se2

ANGLES = np.deg2rad(np.arange(-90.0, 90.0, 10.0))
metres = st.floats(-5.0, 5.0, allow_nan=False)
yaw = st.floats(-math.pi, math.pi, allow_nan=False)


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(x=metres, y=metres, theta=yaw, ros1=st.booleans())
def test_mount_round_trips(x: float, y: float, theta: float, ros1: bool) -> None:
    frames = [
        Frame(i, Scan(np.full(ANGLES.shape, 2.0), ANGLES, 1.0 + i, 10.0), np.array([0.1 * i, 0.0, 0.0]))
        for i in range(2)
    ]
    seq = Sequence.from_frames("m", frames, metadata=SequenceMetadata(sensor_offset=(x, y, theta)))
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / ("m.bag" if ros1 else "m.mcap")
        (Ros1BagWriter() if ros1 else Ros2McapWriter()).write(seq, out)
        loaded = (Ros1BagLoader() if ros1 else Ros2BagLoader()).load(out).metadata.sensor_offset
    assert abs(loaded[0] - x) <= 1e-12 and abs(loaded[1] - y) <= 1e-12
    assert abs(float(se2.wrap(loaded[2] - theta))) <= 1e-12
