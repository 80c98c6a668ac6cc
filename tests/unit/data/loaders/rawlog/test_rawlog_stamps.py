"""Rawlog stamps: usable ones kept, the rest filled in strictly increasing (exact ticks), and what the writer does."""

from __future__ import annotations

import io
import math
import struct

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.loaders.rawlog import serialize as ser
from albot1.data.loaders.rawlog.stamps import START_S, STEP_TICKS, StampClock
from albot1.data.loaders.rawlog.writer import write_frames
from albot1.data.model import Frame, Scan
from albot1.data.retime import RETIME_STEP_S

ANGLES = np.radians(np.linspace(-90.0, 90.0, 5))
T = ser.TICKS_PER_S
S = STEP_TICKS  # 1 us: the step `albot1 convert --retime` uses


def _stamps(seconds: list[float]) -> tuple[list[int], StampClock]:
    clock = StampClock()
    return [clock.stamp(i, s) for i, s in enumerate(seconds)], clock


def test_the_fill_step_is_the_retime_step_in_mrpt_ticks() -> None:
    assert (S, RETIME_STEP_S) == (10, 1e-6)


def test_strictly_increasing_stamps_are_kept_exactly() -> None:
    seconds = [100.0, 100.5, 101.25, 1e9]
    got, clock = _stamps(seconds)
    assert got == [ser.mrpt_timestamp(s) for s in seconds]
    assert (clock.replaced, clock.first_replacement) == (0, None)


def test_constant_stamps_advance_by_one_step_each() -> None:
    got, clock = _stamps([0.0] * 4)
    base = ser.mrpt_timestamp(0.0)
    assert got == [base, base + S, base + 2 * S, base + 3 * S]
    assert clock.replaced == 3
    assert clock.first_replacement == "scan 1: timestamp 0.0 s is not after the previous scan's"


def test_a_repeated_first_stamp_moves_only_that_scan() -> None:
    seconds = [0.0, 0.0] + [round(0.1 * k, 1) for k in range(1, 50)]  # 0, 0, 0.1 .. 4.9
    got, clock = _stamps(seconds)
    assert got == [ser.mrpt_timestamp(0.0), ser.mrpt_timestamp(0.0) + S] + [ser.mrpt_timestamp(s) for s in seconds[2:]]
    assert (len(seconds), clock.replaced) == (51, 1)


def test_a_backward_stamp_moves_one_step_past_the_previous_written_one() -> None:
    got, clock = _stamps([10.0, 10.5, 9.0, 10.5000005, 10.5000021, 11.0])
    # 9.0 goes back: 10.5 s + 1 us; 10.5 s + 0.5 us is not after that: 10.5 s + 2 us; 10.5 s + 2.1 us (one tick
    # after the written stamp) and 11.0 are kept.
    t = ser.mrpt_timestamp(10.5)
    assert got == [ser.mrpt_timestamp(10.0), t, t + S, t + 2 * S, t + 21, ser.mrpt_timestamp(11.0)]
    assert clock.replaced == 2
    assert clock.first_replacement == "scan 2: timestamp 9.0 s is not after the previous scan's"


def test_unusable_stamps_are_filled_and_a_first_one_starts_at_the_unix_epoch() -> None:
    got, clock = _stamps([math.nan, math.inf, -2e10, 5.0])
    base = ser.mrpt_timestamp(START_S)
    assert (START_S, base) == (0.0, ser.FILETIME_EPOCH_OFFSET_S * T)
    assert got == [base, base + S, base + 2 * S, ser.mrpt_timestamp(5.0)]
    assert clock.replaced == 3 and clock.first_replacement == "scan 0: timestamp nan is not finite"


def test_mrpts_invalid_stamp_at_the_first_scan_is_replaced() -> None:
    # Tick 0 is MRPT's INVALID_TIMESTAMP: there is no previous stamp for it to fail to follow.
    invalid = float(-ser.FILETIME_EPOCH_OFFSET_S)
    assert ser.mrpt_timestamp(invalid) == 0
    got, clock = _stamps([invalid, 1.0])
    assert got == [ser.mrpt_timestamp(START_S), ser.mrpt_timestamp(1.0)]
    assert clock.replaced == 1
    assert clock.first_replacement == f"scan 0: timestamp {invalid!r} is MRPT's invalid timestamp"


def test_private_state_is_not_a_constructor_argument() -> None:
    with pytest.raises(TypeError):
        StampClock(_last_ticks=5)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        StampClock(replaced=3)  # type: ignore[call-arg]


def test_a_clock_at_the_end_of_mrpts_range_is_an_error() -> None:
    last = 2**64 / T - ser.FILETIME_EPOCH_OFFSET_S
    while True:  # the largest float second MRPT's clock can hold
        try:
            ticks = ser.mrpt_timestamp(last)
            break
        except ValueError:
            last = math.nextafter(last, -math.inf)
    fills = -(-(2**64 - ticks) // S)  # the fill that would reach 2^64
    clock = StampClock()
    assert clock.stamp(0, last) == ticks
    for k in range(1, fills):
        assert clock.stamp(k, last) == ticks + k * S
    with pytest.raises(DataError, match="no later MRPT timestamp"):
        clock.stamp(fills, last)


finite_or_not = st.one_of(
    st.floats(min_value=-1e3, max_value=1e10, allow_nan=False), st.sampled_from([math.nan, math.inf, -1e11, 0.0])
)


@given(st.lists(finite_or_not, min_size=1, max_size=40))
def test_written_stamps_always_increase_and_usable_increasing_ones_are_kept(seconds: list[float]) -> None:
    got, clock = _stamps(seconds)
    assert all(b > a for a, b in zip(got, got[1:], strict=False))
    own: list[int | None] = []
    for s in seconds:
        try:
            own.append(ser.mrpt_timestamp(s))
        except ValueError:
            own.append(None)
    kept = sum(1 for g, o in zip(got, own, strict=True) if g == o)
    assert clock.replaced == len(seconds) - kept
    if all(o is not None and o > 0 for o in own) and all(
        b > a
        for a, b in zip(own, own[1:], strict=False)  # type: ignore[operator]
    ):
        assert clock.replaced == 0 and got == own


def _frames(seconds: list[float]) -> list[Frame]:
    return [
        Frame(i, Scan(np.full(5, 2.0), ANGLES, s, 30.0), np.array([0.5 * i, 0.0, 0.0])) for i, s in enumerate(seconds)
    ]


def _scan_stamps(blob: bytes) -> list[int]:
    """The stamp of every range scan in an observations-layout rawlog (stamp, beamAperture, then the label)."""
    name = b"mrpt::obs::CObservation2DRangeScan"
    out, k = [], blob.find(name)
    while k >= 0:
        label = blob.find(b"\x05\x00\x00\x00LASER", k)
        out.append(struct.unpack_from("<Q", blob, label - 12)[0])  # then beamAperture (f4), then the label
        k = blob.find(name, label)
    return out


def test_the_writer_fills_only_when_asked_and_is_unchanged_for_usable_stamps() -> None:
    good = _frames([10.0, 10.5, 11.0])
    plain, filled = io.BytesIO(), io.BytesIO()
    write_frames(good, plain, layout="observations")
    stats = write_frames(good, filled, layout="observations", fill_stamps=True)
    assert plain.getvalue() == filled.getvalue() and stats.replaced_stamps == 0
    base = ser.mrpt_timestamp(7.0)
    as_given = io.BytesIO()
    write_frames(_frames([7.0] * 3), as_given, layout="observations")
    assert _scan_stamps(as_given.getvalue()) == [base] * 3
    for layout in ("observations", "actions"):
        out = io.BytesIO()
        stats = write_frames(_frames([7.0] * 3), out, layout=layout, fill_stamps=True)
        assert stats.replaced_stamps == 2
        assert stats.first_replaced_stamp == "scan 1: timestamp 7.0 s is not after the previous scan's"
        assert _scan_stamps(out.getvalue()) == [base, base + S, base + 2 * S]


def test_without_filling_a_non_finite_stamp_is_still_an_error() -> None:
    with pytest.raises(DataError, match="frame 1: timestamp nan is not finite"):
        write_frames(_frames([1.0, math.nan]), io.BytesIO())
    assert write_frames(_frames([1.0, math.nan]), io.BytesIO(), fill_stamps=True).replaced_stamps == 1
