"""The shared "strictly increasing, only as far as needed" rule, and its two users agreeing on it."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from albot1.data.convert import retimed
from albot1.data.loaders.rawlog import serialize as ser
from albot1.data.loaders.rawlog.stamps import StampClock
from albot1.data.model import Frame, Scan
from albot1.data.retime import RETIME_STEP_S, next_stamp


def test_next_stamp_keeps_later_stamps_and_moves_the_rest_one_step_past_the_previous() -> None:
    assert next_stamp(5, None, step=10, resolution=1) == 5
    assert next_stamp(101, 100, step=10, resolution=1) == 101
    assert next_stamp(100, 100, step=10, resolution=1) == 110
    assert next_stamp(3, 100, step=10, resolution=1) == 110
    assert next_stamp(2.0, 1.0, step=RETIME_STEP_S, resolution=RETIME_STEP_S) == 2.0
    assert next_stamp(1.0 + 0.5e-6, 1.0, step=RETIME_STEP_S, resolution=RETIME_STEP_S) == 1.0 + RETIME_STEP_S
    assert math.isnan(next_stamp(math.nan, 1.0, step=RETIME_STEP_S, resolution=RETIME_STEP_S))


def _frames(seconds: list[float]) -> list[Frame]:
    angles = np.radians(np.linspace(-90.0, 90.0, 5))
    return [Frame(i, Scan(np.full(5, 2.0), angles, s, 30.0), np.zeros(3)) for i, s in enumerate(seconds)]


@given(st.lists(st.integers(min_value=0, max_value=60), min_size=1, max_size=40))
def test_retime_and_the_rawlog_clock_move_the_same_stamps_to_the_same_times(micros: list[int]) -> None:
    # On a 1 us grid "at least 1 us later" (retime) and "at least one 100 ns tick later" (rawlog) coincide.
    seconds = [1000.0 + u * 1e-6 for u in micros]
    shifted = [0]
    moved = [ser.mrpt_timestamp(f.scan.timestamp) for f in retimed(iter(_frames(seconds)), shifted)]
    clock = StampClock()
    assert [clock.stamp(i, s) for i, s in enumerate(seconds)] == moved
    assert clock.replaced == shifted[0]
