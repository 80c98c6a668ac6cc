"""``refine_pose`` skips a start equal to an earlier one: the result is the one costing every start gives."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.methods.albot1.compiled import as_written
from albot1.methods.albot1.mapping.pose_kernels import refine_pose, repeats_earlier

# Two walls at right angles seen from the view, their map copies moved by (0.1, -0.05), and points along them.
VIEW = np.array([[-2.0, 3.0, 2.0, 3.0], [2.0, 3.0, 2.0, 0.5]])
MAP = VIEW + np.array([0.1, -0.05, 0.1, -0.05])
POINTS = np.ascontiguousarray(np.vstack([np.column_stack([np.linspace(-2, 2, 9), np.full(9, 3.0)]), [[2.0, 1.0]]]))


def _solve(kernel, starts: np.ndarray) -> tuple[float, float, float, np.ndarray]:
    ok = np.ones((2, 2), dtype=np.bool_)
    return kernel(starts, VIEW, MAP, ok, POINTS, MAP, 0.0, 0.0, 0.0, 0.0, 0.0, 0.05, 0.1, 0.05, 2.0, 0.5, 8, math.inf)


def test_a_repeated_start_is_found_only_after_its_first_occurrence() -> None:
    starts = np.array([[0.0, 0.0, 0.1], [0.2, 0.0, 0.0], [0.0, 0.0, 0.1], [0.0, 0.0, 0.2]])
    assert [repeats_earlier(starts, q) for q in range(4)] == [False, False, True, False]


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "as-written"])
def test_repeated_starts_change_no_bit_of_the_pose_or_the_information(compiled: bool) -> None:
    kernel = refine_pose if compiled else as_written(refine_pose)
    starts = np.array([[0.3, -0.1, 0.05], [0.0, 0.0, 0.0], [0.12, -0.04, 0.01]])
    x, y, phi, info = _solve(kernel, starts)
    assert abs(x - 0.1) < 1e-3 and abs(y + 0.05) < 1e-3 and abs(phi) < 1e-3  # it does fit the moved walls
    for repeated in (starts[[0, 1, 2, 1]], starts[[0, 0, 1, 2, 2]], starts[[2, 1, 0, 2, 1, 0]]):
        rx, ry, rphi, rinfo = _solve(kernel, np.ascontiguousarray(repeated))
        unique = np.ascontiguousarray(repeated[np.sort(np.unique(repeated, axis=0, return_index=True)[1])])
        ux, uy, uphi, uinfo = _solve(kernel, unique)
        assert (rx, ry, rphi) == (ux, uy, uphi)
        assert np.array_equal(rinfo, uinfo)
