"""Localisation (thesis 3.1.6, Algorithm 2, eqs 3.5-3.7): exact rigid geometry and the heuristics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.methods.albot1.mapping.localisation import (
    algorithm2_pose,
    eq_3_6_3_7,
    goodness,
    landmark_pose,
    localise,
    outlier_keep,
)
from albot1.methods.albot1.perception.landmarks import CORNER, OCCLUDING, UNSTABLE
from albot1.methods.albot1.perception.recognition import Tracked


def place(pose: tuple[float, float, float], seg: np.ndarray) -> np.ndarray:
    return se2.transform_points(np.array(pose), seg.reshape(2, 2)).reshape(4)


@pytest.mark.parametrize("side", [0, 1])
@pytest.mark.parametrize("pose", [(1.0, -2.0, 0.7), (-3.5, 0.2, -2.9), (0.0, 0.0, 0.0)])
def test_eqs_3_6_3_7_agree_with_the_exact_rigid_transform(pose: tuple[float, float, float], side: int) -> None:
    view_seg = np.array([-1.2, 2.5, 0.8, 3.1])
    map_seg = place(pose, view_seg)
    # Algorithm 2 literally (two robot points through eqs 3.6-3.7) and the closed form.
    assert algorithm2_pose(map_seg, view_seg, side) == pytest.approx(pose, abs=1e-12)
    assert landmark_pose(map_seg, view_seg, side) == pytest.approx(pose, abs=1e-12)


def test_eq_3_6_3_7_verbatim_on_a_hand_case() -> None:
    # Map surface along +x from (2, 1); a point 1 m away at 90 deg from it lies at (2, 2).
    assert eq_3_6_3_7(2.0, 1.0, 4.0, 1.0, 1.0, math.pi / 2) == pytest.approx((2.0, 2.0))


def test_outlier_rule_drops_the_far_candidate_with_three_or_more() -> None:
    assert outlier_keep([(0.0, 0.0), (0.1, 0.0), (3.0, 0.0)], 3) == [True, True, False]
    # With two candidates both sit at exactly one standard deviation: nothing is dropped.
    assert outlier_keep([(0.0, 0.0), (3.0, 0.0)], 3) == [True, True]
    assert outlier_keep([(0.0, 0.0), (3.0, 0.0)], 2) == [True, True]


def test_goodness_floors_zero_gap_and_angle() -> None:
    assert goodness(1.0, 2.0, 0.0, 0.0, 0.01, 0.001) == pytest.approx(1.0 / (2.0 * 0.01 * 0.001))
    assert goodness(2.0, 1.0, 0.1, 0.1, 0.01, 0.001) > goodness(1.0, 1.0, 0.1, 0.1, 0.01, 0.001)


def tracked(surfaces, kinds, ids, gaps, sides=None) -> Tracked:
    n = len(ids)
    return Tracked(
        np.asarray(surfaces, float),
        np.asarray(kinds, dtype=np.int64),
        np.asarray(ids, dtype=np.int64),
        np.asarray(sides if sides is not None else [0] * n, dtype=np.int64),
        np.asarray(gaps, float),
        np.full(n, math.radians(1.0)),
        np.full(n, 2.0),
        np.full(n, 2.0),
    )


def test_localise_chooses_the_best_goodness_among_consistent_candidates() -> None:
    true = (1.0, 2.0, 0.3)
    views = [np.array([-1.0, 2.0, 0.0, 2.0]), np.array([0.5, 3.0, 1.5, 3.2]), np.array([2.0, 1.0, 2.0, 2.0])]
    landmark_map = {10 + k: (place(true, v), np.array([OCCLUDING, CORNER])) for k, v in enumerate(views)}
    # Landmark 12's map position is 1.5 m off: an outlier.
    landmark_map[12] = (landmark_map[12][0] + np.array([1.5, 0.0, 1.5, 0.0]), landmark_map[12][1])
    kinds = [[OCCLUDING, CORNER]] * 3
    # Landmark 11 has the smallest gap (highest goodness) among the consistent two.
    rl = tracked(views, kinds, [10, 11, 12], [0.2, 0.05, 0.01])
    loc = localise(rl, landmark_map, min_candidates=3, gap_floor=0.01, angle_floor=math.radians(0.1))
    assert loc is not None
    assert loc.kept.tolist() == [True, True, False]
    assert loc.reference_id == 11
    assert loc.pose == pytest.approx(true, abs=1e-12)


def test_localise_uses_p2_when_only_p2_is_stable_and_skips_unusable_landmarks() -> None:
    true = (-0.5, 0.4, -1.0)
    view = np.array([-1.0, 2.0, 0.0, 2.5])
    landmark_map = {
        5: (place(true, view), np.array([UNSTABLE, CORNER])),
        6: (place(true, view), np.array([UNSTABLE, UNSTABLE])),
    }
    rl = tracked([view, view], [[OCCLUDING, CORNER], [OCCLUDING, CORNER]], [5, 6], [0.1, 0.1])
    loc = localise(rl, landmark_map, min_candidates=3, gap_floor=0.01, angle_floor=0.001)
    assert loc is not None and loc.candidate_ids.tolist() == [5]
    assert loc.pose == pytest.approx(true, abs=1e-12)
    assert (
        localise(
            tracked([view], [[OCCLUDING, CORNER]], [6], [0.1]),
            landmark_map,
            min_candidates=3,
            gap_floor=0.01,
            angle_floor=0.001,
        )
        is None
    )
