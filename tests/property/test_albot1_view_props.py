"""Invariants of view construction on arbitrary scans (hypothesis)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.methods.albot1.perception.kernels import PerceptionKernels
from albot1.methods.albot1.perception.landmarks import CORNER, OCCLUDED, OCCLUDING, UNSTABLE
from albot1.methods.albot1.perception.view import ViewParams, construct_view

ANGLES = np.radians(np.arange(-90.0, 91.0, 2.0))
ranges_strategy = st.lists(
    st.one_of(st.floats(0.05, 40.0), st.just(math.nan)),
    min_size=ANGLES.size,
    max_size=ANGLES.size,
).map(np.array)


@settings(max_examples=60, deadline=None)
@given(ranges_strategy)
def test_view_invariants(ranges: np.ndarray) -> None:
    params = ViewParams()
    view = construct_view(ranges, ANGLES, params)
    assert np.all(view.lengths >= params.surface_length)
    assert set(np.unique(view.kinds).tolist()) <= {UNSTABLE, OCCLUDING, CORNER, OCCLUDED}
    # Endpoints are scan points (thesis frame) on the beams named, within max_range.
    rev_r, rev_a = ranges[::-1], ANGLES[::-1]
    for s, b in zip(view.surfaces, view.beams):
        for e in (0, 1):
            r, a = rev_r[b[e]], rev_a[b[e]]
            assert r <= params.max_range
            np.testing.assert_allclose(s[2 * e : 2 * e + 2], [-r * math.sin(a), r * math.cos(a)], atol=1e-9)
    # Left to right: beams never go backwards; a surface spans beams b1 <= b2.
    flat = view.beams.ravel()
    assert np.all(np.diff(flat) >= 0)
    # Same result from the interpreted kernels.
    plain = construct_view(ranges, ANGLES, params, PerceptionKernels(False))
    np.testing.assert_array_equal(plain.surfaces, view.surfaces)
    np.testing.assert_array_equal(plain.kinds, view.kinds)
