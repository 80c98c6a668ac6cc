"""The kernels' stable order is numpy's ``argsort(kind="stable")``, compiled and as written, on float and int arrays.

The kernels use :func:`albot1.methods.albot1.ordering.stable_order` instead
of numba's merge sort only because it compiles faster; any difference in
order would change which landmark pairs and exits are chosen.
"""

from __future__ import annotations

import numba
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from albot1.methods.albot1.ordering import stable_order

compiled_order = numba.njit(lambda values: stable_order(values))

#: few distinct values (ties), signed zeros, infinities and NaN: what decides a stable order
VALUES = st.sampled_from([0.0, -0.0, 1.0, -1.0, 2.5, np.inf, -np.inf, np.nan]) | st.floats(allow_nan=True)


def test_examples() -> None:
    assert stable_order(np.array([2.0, 1.0, 2.0, np.nan, 1.0, -np.inf])).tolist() == [5, 1, 4, 0, 2, 3]
    assert stable_order(np.empty(0)).tolist() == [] and stable_order(np.array([3.0])).tolist() == [0]
    assert compiled_order(np.array([0.0, -0.0, np.nan, 0.0])).tolist() == [0, 1, 3, 2]


@settings(deadline=None)  # the first example compiles the float version when test_examples did not run first
@given(arrays(np.float64, st.integers(0, 70), elements=VALUES))
def test_the_order_is_numpy_s_stable_argsort_compiled_and_as_written(values: np.ndarray) -> None:
    expected = np.argsort(values, kind="stable")
    assert stable_order(values).tolist() == expected.tolist()
    got = compiled_order(values)
    assert got.dtype == np.int64 and got.tolist() == expected.tolist()


@settings(deadline=None)  # the first example compiles the integer version
@given(arrays(np.int64, st.integers(0, 70), elements=st.integers(-3, 3) | st.integers(-(2**63), 2**63 - 1)))
def test_integer_arrays_too(values: np.ndarray) -> None:
    """``update_surfaces`` orders its candidate surface ids with it (an integer array)."""
    expected = np.argsort(values, kind="stable")
    assert stable_order(values).tolist() == expected.tolist()
    assert compiled_order(values).tolist() == expected.tolist()
