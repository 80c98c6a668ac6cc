"""A LaserScan's beams as the data model's (angle, range) pairs, against a hand computation, for either sign of
``angle_increment`` (a clockwise or reversed scanner) and REP 117's non-finite ranges.

Beam ``i`` of a message is at ``angle_min + i * angle_increment`` (from the message's float32 fields, in float64)
and measured ``ranges[i]``; a reading that is not finite (``+inf`` nothing within range, ``-inf`` too close,
NaN an error), outside ``[range_min, range_max]`` or exactly 0 is no return (NaN). The loader may reorder the beams
(a negative increment is reversed so that angles ascend) and drops the repeated direction of a 360-degree scan
listed with both ends, but every other beam must keep its own range: a mirrored scan would pair each range with
the opposite beam's angle.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.loaders.rosbag.msg import laserscan_problem, scan_arrays

READING = st.one_of(
    st.floats(0.0, 80.0, width=32),
    st.sampled_from([math.inf, -math.inf, math.nan, 0.0, -1.0, 1e-3]),
)


@st.composite
def laser_scans(draw: st.DrawFn) -> tuple[np.ndarray, float, float, float, float, float]:
    """``(ranges, angle_min, angle_max, angle_increment, range_min, range_max)`` as float32 message fields."""
    n = draw(st.integers(1, 400))
    largest_step = 2 * math.pi / max(n - 1, 1)
    step = draw(st.floats(1e-4, largest_step)) * draw(st.sampled_from([1.0, -1.0]))
    if n > 2 and draw(st.booleans()):  # a 360-degree scanner listing its first direction twice
        step = math.copysign(2 * math.pi / (n - 1), step)
    f32 = np.float32
    angle_min = float(f32(draw(st.floats(-math.pi, math.pi))))
    step = float(f32(step))
    range_min = float(f32(draw(st.floats(0.0, 1.0))))
    range_max = float(f32(range_min + draw(st.floats(0.5, 60.0))))
    angle_max = float(f32(angle_min + (n - 1) * step))
    ranges = np.array(draw(st.lists(READING, min_size=n, max_size=n)), dtype=np.float32)
    return ranges, angle_min, angle_max, step, range_min, range_max


def _by_hand(
    ranges: np.ndarray, angle_min: float, step: float, range_min: float, range_max: float
) -> list[tuple[float, float]]:
    """Every beam's (angle, range or NaN), one at a time, in the message's order."""
    out = []
    for i, value in enumerate(ranges.tolist()):
        keep = math.isfinite(value) and range_min <= value <= range_max and value != 0.0
        out.append((angle_min + i * step, value if keep else math.nan))
    n = len(out)
    if n >= 3 and abs(abs(out[-1][0] - out[0][0]) - 2 * math.pi) <= abs(step) / 4:
        out.pop()  # the repeated first direction of a 360-degree scan
    return out


@pytest.mark.slow
@settings(max_examples=100, deadline=None)
@given(laser_scans())
def test_each_beam_keeps_its_own_range_whatever_the_increment_sign(
    scan: tuple[np.ndarray, float, float, float, float, float],
) -> None:
    ranges, angle_min, angle_max, step, range_min, range_max = scan
    assert laserscan_problem(len(ranges), angle_min, angle_max, step, range_min, range_max) is None
    got_r, got_a = scan_arrays(ranges, angle_min, step, range_min, range_max)
    expected = sorted(_by_hand(ranges, angle_min, step, range_min, range_max))
    assert got_a.tolist() == [a for a, _ in expected]  # ascending, exactly the hand-computed angles
    np.testing.assert_array_equal(got_r, [r for _, r in expected])  # NaN where no return, else the reading
    assert bool(np.all(np.diff(got_a) > 0))
    # the points themselves: a beam at the left (angle > 0) stays on the left
    hits = ~np.isnan(got_r)
    ys = got_r[hits] * np.sin(got_a[hits])
    hand = [r * math.sin(a) for a, r in expected if not math.isnan(r)]
    np.testing.assert_allclose(ys, hand, rtol=0, atol=1e-12)
