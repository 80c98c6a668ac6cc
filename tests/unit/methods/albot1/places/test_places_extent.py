"""``colocated``'s polygon extent is numpy's column min and max, compiled and as written (NaN and empty included).

The loop replaced ``poly[:, axis].min()``/``.max()`` only because it compiles
faster; a different extent would change which remembered surfaces a view
co-locates with.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from albot1.methods.albot1.places.surface_kernels import _extent

compiled_extent = numba.njit(lambda points, axis: _extent(points, axis))

VALUES = st.sampled_from([0.0, -0.0, 1.0, -2.5, np.inf, -np.inf, np.nan]) | st.floats(allow_nan=True)


def test_examples() -> None:
    poly = np.array([[1.0, -2.0], [-3.0, 4.0], [0.5, 0.0]])
    assert _extent(poly, 0) == (-3.0, 1.0) and _extent(poly, 1) == (-2.0, 4.0)
    assert compiled_extent(poly, 0) == (-3.0, 1.0) and compiled_extent(poly, 1) == (-2.0, 4.0)
    with_nan = np.array([[1.0, 0.0], [np.nan, 1.0], [-1.0, 2.0]])
    assert all(np.isnan(v) for v in _extent(with_nan, 0)) and _extent(with_nan, 1) == (0.0, 2.0)


def test_an_empty_polygon_raises_numpy_s_error() -> None:
    with pytest.raises(ValueError, match="zero-size array"):
        _extent(np.empty((0, 2)), 0)
    with pytest.raises(ValueError, match="zero-size array"):
        compiled_extent(np.empty((0, 2)), 0)


@settings(deadline=None)  # the first example compiles
@given(arrays(np.float64, st.tuples(st.integers(1, 30), st.just(2)), elements=VALUES), st.integers(0, 1))
def test_the_extent_is_numpy_s_min_and_max(points: np.ndarray, axis: int) -> None:
    expected = np.array([points[:, axis].min(), points[:, axis].max()])
    for got in (_extent(points, axis), compiled_extent(points, axis)):
        np.testing.assert_array_equal(np.array(got), expected)
