"""``refine_pose`` skips a start equal to an earlier one, and stops costing a start that cannot win: the result is
the one costing every start in full gives."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from albot1.geometry.segments import closest_parameter
from albot1.methods.albot1.compiled import as_written
from albot1.methods.albot1.mapping import pose_kernels
from albot1.methods.albot1.mapping.overlap import NO_LIMIT, overhangs
from albot1.methods.albot1.mapping.pose_kernels import pose_cost, refine_pose, repeats_earlier, surface_boxes

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


def _cost(x: float, y: float, phi: float, bound: float) -> float:
    ok = np.ones((2, 2), dtype=np.bool_)
    boxes = surface_boxes(MAP, 0.5)
    return float(pose_cost(x, y, phi, VIEW, MAP, ok, POINTS, MAP, boxes, 0.05, 0.1, 0.05, 2.0, 0.5, math.inf, bound))


def test_a_bounded_cost_is_the_full_cost_below_the_bound_and_at_least_the_bound_from_it() -> None:
    rng = np.random.default_rng(7)
    stopped = 0
    for x, y, phi in rng.uniform([-0.4, -0.4, -0.3], [0.4, 0.4, 0.3], size=(200, 3)):
        full = _cost(x, y, phi, math.inf)
        for bound in (0.0, 0.5 * full, full, np.nextafter(full, math.inf), 2.0 * full, math.inf):
            bounded = _cost(x, y, phi, bound)
            if full < bound:
                assert bounded == full  # the same terms in the same order: the same bits
            else:
                assert bound <= bounded <= full
                stopped += bounded < full
    assert stopped > 100  # the bound does cut sums short


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "as-written"])
def test_the_start_chosen_with_cut_short_costs_is_the_cheapest_by_full_costs(compiled: bool) -> None:
    kernel = refine_pose if compiled else as_written(refine_pose)
    rng = np.random.default_rng(11)
    for _ in range(30):
        starts = np.ascontiguousarray(rng.uniform([-0.4, -0.4, -0.3], [0.4, 0.4, 0.3], size=(6, 3)))
        full = [_cost(*start, math.inf) for start in starts]
        cheapest = np.ascontiguousarray(starts[[int(np.argmin(full))]])  # argmin: the first lowest, as the kernel
        x, y, phi, info = _solve(kernel, starts)
        cx, cy, cphi, cinfo = _solve(kernel, cheapest)
        assert (x, y, phi) == (cx, cy, cphi)
        assert np.array_equal(info, cinfo)


def _nearest_by_the_rule(x: float, y: float, ref: np.ndarray, gate: float, overhang: float) -> tuple[int, float]:
    """The nearest surface as the rule states it: every surface, the overlap test, then ``hypot`` to the segment."""
    best, found = gate, -1
    for j, (ax, ay, bx, by) in enumerate(ref.tolist()):
        if overhangs(x, y, ax, ay, bx, by, overhang):
            continue
        t = closest_parameter(x, y, ax, ay, bx, by)
        d = float(np.hypot(ax + t * (bx - ax) - x, ay + t * (by - ay) - y))
        if d < best:
            best, found = d, j
    return found, best


@numba.njit(cache=False)
def _nearest_compiled(x: float, y: float, ref: np.ndarray, boxes: np.ndarray, gate: float, overhang: float):  # type: ignore[no-untyped-def]
    return pose_kernels.nearest_surface(x, y, ref, boxes, gate, overhang)


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "as-written"])
@pytest.mark.parametrize("overhang", [NO_LIMIT, 0.0, 0.2])
def test_the_nearest_surface_is_the_one_the_rule_gives_to_the_bit(compiled: bool, overhang: float) -> None:
    # Per-surface terms computed once and hypot skipped where the squared distance settles the comparison: the
    # same surface and the same distance as every surface measured in full, including ties (mirrored surfaces
    # at one distance, a repeated surface), degenerate surfaces and points on a surface.
    nearest = _nearest_compiled if compiled else pose_kernels.nearest_surface
    rng = np.random.default_rng(5)
    walls = rng.uniform(-1.0, 1.0, size=(12, 4))
    walls[3] = walls[2]  # a repeated surface: the first keeps it
    walls[4, 2:] = walls[4, :2]  # a degenerate one
    mirrored = np.array([[-0.5, -0.3, -0.5, 0.3], [0.5, -0.3, 0.5, 0.3]])  # the y axis is equidistant to both
    ref = np.ascontiguousarray(np.vstack([walls, mirrored]))
    boxes = pose_kernels.surface_boxes(ref, 0.5)
    points = np.vstack(
        [rng.uniform(-1.5, 1.5, size=(400, 2)), np.column_stack([np.zeros(5), np.linspace(-0.2, 0.2, 5)])]
    )
    points = np.vstack([points, ref[:, :2], ref[:, 2:]])  # points on surfaces' ends
    for x, y in points.tolist():
        assert nearest(x, y, ref, boxes, 0.5, overhang) == _nearest_by_the_rule(x, y, ref, 0.5, overhang)
