"""The overlap rule (``scan_overlap = "surface"``): a view point is matched to a surface only where it was seen."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.methods.albot1.compiled import as_written
from albot1.methods.albot1.mapping.ambiguity import measurement_costs
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.overlap import NO_LIMIT, overhangs
from albot1.methods.albot1.mapping.pose_kernels import nearest_surface, refine_pose, surface_boxes

WALL = (0.0, 5.0, 2.0, 5.0)  # a wall 2 m long along x


@pytest.mark.parametrize(
    ("x", "limit", "expected"),
    [
        (1.0, 0.0, False),  # on the surface
        (2.3, 0.2, True),  # 0.3 m beyond its end
        (2.3, 0.35, False),
        (-0.3, 0.2, True),  # 0.3 m before its start
        (-0.3, 0.35, False),
        (2.3, NO_LIMIT, False),  # no limit: never excluded
        (1e6, NO_LIMIT, False),
    ],
)
def test_a_projection_overhangs_by_more_than_the_limit(x: float, limit: float, expected: bool) -> None:
    assert overhangs(x, 5.2, *WALL, limit) is expected


def test_a_degenerate_surface_is_never_excluded() -> None:
    assert overhangs(0.3, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0) is False


def test_a_point_beyond_a_surface_end_goes_to_the_surface_it_projects_on() -> None:
    # The point is 0.3 m beyond WALL's end; a second wall 0.4 m to its right is where its projection falls.
    ref = np.array([WALL, (2.7, 4.0, 2.7, 6.0)])
    boxes = surface_boxes(ref, 0.5)
    assert nearest_surface(2.3, 5.0, ref, boxes, 0.5, NO_LIMIT) == (0, pytest.approx(0.3))
    assert nearest_surface(2.3, 5.0, ref, boxes, 0.5, 0.35) == (0, pytest.approx(0.3))
    assert nearest_surface(2.3, 5.0, ref, boxes, 0.5, 0.0) == (1, pytest.approx(0.4))
    # Without the second wall nothing takes it: unmatched, at the gate's distance.
    assert nearest_surface(2.3, 5.0, ref[:1], boxes[:1], 0.5, 0.0) == (-1, 0.5)


# The last update view (thesis frame, robot at the origin facing +y): a back wall that ends at x = 3 and a side
# wall. The new view, from the same pose, also sees a wall the update view did not: from the back wall's end
# away at 45 deg (the far side of a corner). Its first 0.35 m lie within the 0.5 m gate of the back wall's end.
UPDATE_VIEW = np.array([[-3.0, 5.0, 3.0, 5.0], [-3.0, 0.5, -3.0, 5.0]])
NEW_WALL = np.array([3.0, 5.0, 5.0, 3.0])


def _points() -> np.ndarray:
    parts = []
    for x1, y1, x2, y2 in (*UPDATE_VIEW, NEW_WALL):
        t = np.linspace(0.0, 1.0, int(math.hypot(x2 - x1, y2 - y1) / 0.05) + 1)[1:-1]
        parts.append(np.column_stack([x1 + t * (x2 - x1), y1 + t * (y2 - y1)]))
    return np.ascontiguousarray(np.vstack(parts))


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "as-written"])
def test_points_past_a_corner_the_update_view_did_not_see_no_longer_turn_the_fit(compiled: bool) -> None:
    """With perfect data the fit should stay at the true pose (the origin); matched to the back wall's extension,
    the new wall's points pull it off; with the overlap rule they are unmatched and the fit is exact."""
    kernel = refine_pose if compiled else as_written(refine_pose)
    none4 = np.empty((0, 4))
    none2 = np.empty((0, 2), dtype=np.bool_)
    args = (np.zeros((1, 3)), none4, none4, none2, _points(), UPDATE_VIEW, 0.0, 0.0, 0.0, 0.0, 0.0)
    sigmas = (0.05, 0.1, 0.05, 2.0, 0.5, 20)
    x, y, phi, _ = kernel(*args, *sigmas, NO_LIMIT)
    assert abs(x) + abs(y) > 1e-3 or abs(phi) > 1e-4  # pulled off the true pose
    x, y, phi, _ = kernel(*args, *sigmas, 0.0)
    assert max(abs(x), abs(y), abs(phi)) < 1e-9


def test_the_rule_is_off_unless_asked_for_and_then_carries_its_overhang() -> None:
    assert Albot1Config().plus_params().overhang == NO_LIMIT
    assert Albot1Config(scan_overhang_m=0.2).plus_params().overhang == NO_LIMIT  # "gate": the overhang is unused
    assert Albot1Config(scan_overlap="surface", scan_overhang_m=0.2).plus_params().overhang == 0.2


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "as-written"])
def test_the_ambiguity_costs_use_the_same_rule(compiled: bool) -> None:
    """A point 0.3 m past the wall's end, 0.1 m off its line: matched without the rule (the cost counts its
    distance to the segment, hypot(0.3, 0.1) / 0.05 = 6.3 sigmas, Huber linear beyond 2: 2 * (6.3 - 1)), unmatched
    with it (the gate's cost: 10 sigmas, 2 * (10 - 1) = 18)."""
    kernel = measurement_costs if compiled else as_written(measurement_costs)
    none4 = np.empty((0, 4))
    none2 = np.empty((0, 2), dtype=np.bool_)
    points = np.array([[2.3, 5.1]])
    ref = np.array([WALL])
    past = 2.0 * (math.hypot(0.3, 0.1) / 0.05 - 1.0)
    for overhang, cost, matched in ((NO_LIMIT, past, [1]), (0.0, 18.0, [0])):
        costs, per_surface, matched_cost, *_ = kernel(
            np.zeros((1, 3)), none4, none4, none2, points, ref, 0.05, 0.1, 0.05, 2.0, 0.5, overhang
        )
        assert costs[0] == pytest.approx(cost) and per_surface.tolist() == matched
        assert matched_cost == pytest.approx(cost if matched == [1] else 0.0)
