"""Localisation (thesis 3.1.6, Algorithm 2, eqs 3.5-3.7): exact rigid geometry and the heuristics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.localisation import (
    algorithm2_pose,
    eq_3_6_3_7,
    goodness,
    landmark_pose,
    localise,
    outlier_keep,
)
from albot1.methods.albot1.perception.landmarks import CORNER, OCCLUDING, UNSTABLE
from albot1.methods.albot1.perception.recognition import Tracked, recognise


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


def compiled_choice(rl: Tracked, landmark_map: dict, min_candidates: int, gap_floor: float, angle_floor: float):
    """The mapper's path for every preset: the compiled localisation (``robust_starts``) on the same inputs."""
    ids = np.asarray(list(landmark_map), dtype=np.int64)
    segs = np.asarray([landmark_map[i][0] for i in ids], dtype=float).reshape(-1, 4)
    kinds = np.asarray([landmark_map[i][1] for i in ids], dtype=np.int64).reshape(-1, 2)
    starts, _, _, _, best = MappingKernels(True).robust_starts(
        rl.surfaces, rl.kinds, rl.ids, rl.side, rl.prev_distance, rl.gap, rl.angle_diff, ids, segs, kinds,
        0.0, 0.0, 0.0, np.empty(0), min_candidates, gap_floor, angle_floor,
    )  # fmt: skip
    return tuple(starts[0].tolist()), int(rl.ids[best])


def test_goodness_takes_its_terms_from_the_match_and_the_current_surface() -> None:
    # Eq. 3.5: goodness = S_L / (d_R x g_diff x a_diff), "d_R is the distance of the occluding point of S_{n-1} from
    # Albot1, g_diff is the gap length between the occluding points of S_n and S_{n-1}, a_diff is the angular
    # difference between S_n and S_{n-1}, and S_L is the length of the surface S_n"; the highest wins (3.1.6).
    # The previous view is the update view (the map frame); the robot then moved 0.5 m forward (thesis frame +y).
    # Landmark 1: 1 m long at 4.12 m, seen again 2 cm off and now 3 m long (its right end was hidden before).
    # Landmark 2: 1 m long at 2.24 m, seen again 3 cm off. Both directions unchanged (a_diff floored).
    gap_floor, angle_floor = 0.01, math.radians(0.1)
    prev_segs = np.array([[-1.0, 4.0, 0.0, 4.0], [1.0, 2.0, 2.0, 2.0]])
    kinds = np.array([[OCCLUDING, UNSTABLE]] * 2)
    previous = Tracked.fresh(prev_segs, kinds, np.array([1, 2]))
    current = np.array([[-0.98, 3.5, 2.02, 3.5], [1.03, 1.5, 2.03, 1.5]])
    rl = recognise(previous, current, kinds, (0.0, 0.5, 0.0), max_angle=math.radians(5.0), max_distance=0.4)
    assert rl.ids.tolist() == [1, 2] and rl.side.tolist() == [0, 0]
    np.testing.assert_allclose(rl.gap, [0.02, 0.03], atol=1e-12)
    np.testing.assert_allclose(rl.angle_diff, [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(rl.prev_distance, [math.sqrt(17.0), math.sqrt(5.0)], rtol=1e-15)
    landmark_map = {1: (prev_segs[0], kinds[0]), 2: (prev_segs[1], kinds[1])}
    loc = localise(rl, landmark_map, min_candidates=3, gap_floor=gap_floor, angle_floor=angle_floor)
    assert loc is not None
    want = [3.0 / (math.sqrt(17.0) * 0.02 * angle_floor), 1.0 / (math.sqrt(5.0) * 0.03 * angle_floor)]
    np.testing.assert_allclose(loc.goodness, want, rtol=1e-9)
    # 36.4 against 14.9 (over angle_floor): landmark 1. With the previous or the map surface's length (1 m) it
    # would be 12.1 and landmark 2 would win, so this pins S_L to S_n.
    assert loc.reference_id == 1
    # Landmark 1's reference point (its P1) moved 2 cm right, so the robot is placed 2 cm left of its true (0, 0.5).
    assert loc.pose == pytest.approx((-0.02, 0.5, 0.0), abs=1e-12)
    pose, reference = compiled_choice(rl, landmark_map, 3, gap_floor, angle_floor)
    assert reference == 1 and pose == pytest.approx(loc.pose, abs=0.0)


@pytest.mark.parametrize(("side", "anchor"), [(1, 1), (0, 0), (-1, 0)])
def test_the_reference_point_is_the_matched_endpoint_when_both_are_stable(side: int, anchor: int) -> None:
    # Eqs 3.6-3.7 walk from the map surface's reference point; the thesis's worked case uses P1 ("in this case first
    # point of surface is reference point") and names the occluding point as the reference of eq. 3.5's terms. The
    # code takes the endpoint the recognition matched (stable in both views and in the map record), P1 for a list
    # with no match data (docs/albot1-mapper.md items 15-16, note 11). Here both ends are stable everywhere but
    # the map copy's P1 lies 0.2 m further along the surface: anchored at P2 the pose is exact, at P1 it is
    # shifted by 0.2 m along the map surface's direction.
    true = (0.7, -1.2, 0.4)
    view = np.array([-1.0, 2.0, 1.0, 2.5])
    map_seg = place(true, view)
    direction = (map_seg[2:] - map_seg[:2]) / np.hypot(*(map_seg[2:] - map_seg[:2]))
    map_seg[:2] += 0.2 * direction
    both = [[OCCLUDING, CORNER]]
    landmark_map = {3: (map_seg, np.array([OCCLUDING, CORNER]))}
    rl = tracked([view], both, [3], [0.05], sides=[side])
    loc = localise(rl, landmark_map, min_candidates=3, gap_floor=0.01, angle_floor=0.001)
    assert loc is not None
    shift = 0.2 * direction if anchor == 0 else np.zeros(2)
    assert loc.pose == pytest.approx((true[0] + shift[0], true[1] + shift[1], true[2]), abs=1e-12)
    pose, _ = compiled_choice(rl, landmark_map, 3, 0.01, 0.001)
    assert pose == pytest.approx(loc.pose, abs=0.0)
