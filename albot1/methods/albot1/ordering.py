"""The stable ascending order of a 1-D array inside a kernel: numpy's ``argsort(kind="stable")``, cheaper to compile.

Why not ``np.argsort(values, kind="mergesort")`` in the kernels: numba
compiles its generic merge sort into every kernel that calls it, about 1 s
of a cold compile each (a sixth of the Albot1 kernels' compile; see
``docs/albot1-mapper.md``, "Kernels"). This bottom-up merge sort is the
same order: a stable sort's order is unique (equal values keep their index
order), and ``NaN`` sorts last as in numpy. The parity tests compare it with
``np.argsort(kind="stable")``, compiled and as written.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import jitable


@jitable
def _before(a: float, b: float) -> bool:
    """numpy's sort order: ``a`` strictly before ``b`` (every number before ``NaN``)."""
    return a < b or (b != b and a == a)


@jitable
def stable_order(values: FloatArray | NDArray[np.int64]) -> NDArray[np.int64]:
    """The indices that sort ``values`` (1-D, float or integer) ascending, equal values in index order, ``NaN`` last."""
    n = values.shape[0]
    order = np.empty(n, dtype=np.int64)
    for i in range(n):  # a loop, not np.arange: one numpy routine less to compile
        order[i] = i
    spare = np.empty(n, dtype=np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid = min(lo + width, n)
            hi = min(lo + 2 * width, n)
            i = lo
            j = mid
            for k in range(lo, hi):
                # take from the left run unless the right one's head is strictly before it: stable
                if i < mid and (j >= hi or not _before(values[order[j]], values[order[i]])):
                    spare[k] = order[i]
                    i += 1
                else:
                    spare[k] = order[j]
                    j += 1
        order, spare = spare, order
        width *= 2
    return order
