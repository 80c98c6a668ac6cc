"""Segment distance on arbitrary segments (hypothesis): a metric-like, frame-independent quantity."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from albot1.geometry import se2
from albot1.geometry.segments import point_segment_distance, segment_distance, segments_cross, transform_segments

coord = st.floats(-50.0, 50.0, allow_nan=False)
segment = st.tuples(coord, coord, coord, coord).map(lambda t: np.array(t, dtype=float))
pose = st.tuples(coord, coord, st.floats(-4.0, 4.0)).map(lambda t: np.array(t, dtype=float))


@given(segment, segment)
def test_symmetric_and_at_most_the_nearest_endpoint_pair(a: np.ndarray, b: np.ndarray) -> None:
    d = segment_distance(a, b)
    if segments_cross(a, b) == segments_cross(b, a):
        assert d == segment_distance(b, a)
    else:
        # The crossing test is strict on a's endpoints and not on b's: when an endpoint lies exactly
        # on the other line (touching), one order reports 0 and the other the rounding-level gap.
        assert math.isclose(d, segment_distance(b, a), abs_tol=1e-9)
    ends = min(math.hypot(a[i] - b[j], a[i + 1] - b[j + 1]) for i in (0, 2) for j in (0, 2))
    # Projections round: a shared endpoint can come out 1e-213 apart instead of 0.
    assert 0.0 <= d <= ends + 1e-9
    assert d <= point_segment_distance(a[0], a[1], b)
    if segments_cross(a, b):
        assert d == 0.0


@given(segment, segment, pose)
def test_invariant_under_a_rigid_motion(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> None:
    moved = transform_segments(p, np.stack([a, b]))
    assert math.isclose(segment_distance(moved[0], moved[1]), segment_distance(a, b), rel_tol=1e-9, abs_tol=1e-9)
    np.testing.assert_allclose(moved[0].reshape(2, 2), se2.transform_points(p, a.reshape(2, 2)), rtol=1e-12, atol=1e-12)
