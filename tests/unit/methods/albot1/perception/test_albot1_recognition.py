"""Landmark recognition (thesis 3.1.5, Algorithm 1, eqs 3.1-3.4) with known motions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.synthetic.lidar import cast
from albot1.geometry import se2
from albot1.methods.albot1.perception.frames import rep_to_thesis_pose
from albot1.methods.albot1.perception.kernels import PerceptionKernels
from albot1.methods.albot1.perception.landmarks import CORNER, OCCLUDING, UNSTABLE, find_landmarks
from albot1.methods.albot1.perception.recognition import Tracked, motion_step, recognise, thesis_motion
from albot1.methods.albot1.perception.view import ViewParams, construct_view

ANGLES = np.radians(np.arange(-90.0, 91.0, 0.5))
# A room with a pillar and a recess: several corner and occluding landmarks in view.
WALLS = np.array(
    [
        [-2.0, -4.0, 8.0, -4.0],
        [8.0, -4.0, 8.0, 1.0],
        [8.0, 1.0, 9.5, 1.0],
        [9.5, 1.0, 9.5, 3.0],
        [9.5, 3.0, 8.0, 3.0],
        [8.0, 3.0, 8.0, 5.0],
        [8.0, 5.0, -2.0, 5.0],
        [4.0, -1.5, 5.0, -1.5],
        [5.0, -1.5, 5.0, -0.5],
        [5.0, -0.5, 4.0, -0.5],
        [4.0, -0.5, 4.0, -1.5],
    ]
)
MAX_ANGLE, MAX_DISTANCE = math.radians(5.0), 0.4


def landmarks_at(pose: np.ndarray):
    ranges = cast(WALLS, pose, ANGLES, 30.0)
    return find_landmarks(construct_view(ranges, ANGLES, ViewParams()), 0.4)


def to_world(pose_rep: np.ndarray, segs: np.ndarray) -> np.ndarray:
    """Thesis-frame view segments -> REP world points (m, 2, 2)."""
    pts = segs.reshape(-1, 2)
    rep = np.column_stack([pts[:, 1], -pts[:, 0]])
    return se2.transform_points(pose_rep, rep).reshape(-1, 2, 2)


def test_eqs_3_1_3_2_place_the_robot_along_its_turned_heading() -> None:
    x, y, th = thesis_motion(1.0, math.pi / 2)
    assert (x, y, th) == pytest.approx((-1.0, 0.0, math.pi / 2), abs=1e-12)
    assert motion_step((0.3, 0.0, 0.0), "thesis") == pytest.approx(motion_step((0.3, 0.0, 0.0), "exact"))
    # Continuous motion: forward 1 m while turning 30 deg; the models disagree.
    assert motion_step((1.0, 0.0, math.radians(30)), "exact") == pytest.approx((0.0, 1.0, math.radians(30)))
    assert motion_step((1.0, 0.0, math.radians(30)), "thesis") == pytest.approx(
        (-0.5, math.sqrt(3) / 2, math.radians(30))
    )


@pytest.mark.parametrize("accelerate", [True, False])
def test_eqs_3_3_3_4_in_the_kernel_equal_the_inverse_rigid_motion(accelerate: bool) -> None:
    # The kernel predicts the previous surface into the current view (eqs 3.3-3.4); a current
    # surface placed exactly where the inverse rigid motion puts it is matched with zero gap,
    # and its predicted endpoint's distance from the robot is reported.
    step = (0.4, 1.2, math.radians(25.0))
    seg = np.array([[1.0, 2.0, -0.5, 3.0]])
    want = se2.transform_points(se2.inverse(np.array(step)), seg.reshape(2, 2)).reshape(1, 4)
    kinds = np.array([[OCCLUDING, CORNER]])
    kernel = PerceptionKernels(accelerate).recognise_landmarks
    i, j, side, gap, angle_diff, d_prev, d_pred = kernel(seg, kinds, want, kinds, *step, MAX_ANGLE, MAX_DISTANCE, True)
    assert (i.tolist(), j.tolist(), side.tolist()) == ([0], [0], [0])
    assert gap[0] == pytest.approx(0.0, abs=1e-12) and angle_diff[0] == pytest.approx(0.0, abs=1e-12)
    assert d_prev[0] == pytest.approx(math.hypot(1.0, 2.0))
    assert d_pred[0] == pytest.approx(math.hypot(want[0, 0], want[0, 1]))
    # Moved by 0.3 m along x in the current view: the gap is that shift.
    shifted = want + [0.3, 0.0, 0.3, 0.0]
    gap_shifted = kernel(seg, kinds, shifted, kinds, *step, MAX_ANGLE, MAX_DISTANCE, True)[3]
    assert gap_shifted[0] == pytest.approx(0.3)


@pytest.mark.parametrize("motion", [(0.25, 0.0, 3.0), (0.3, 0.05, -4.0), (0.0, 0.0, 0.0), (0.0, 0.0, 2.5)])
def test_known_rigid_motion_recognises_every_landmark_with_its_id(motion: tuple[float, float, float]) -> None:
    pose_a = np.array([0.0, 0.0, 0.0])
    step_rep = np.array([motion[0], motion[1], math.radians(motion[2])])
    pose_b = se2.compose(pose_a, step_rep)
    la, lb = landmarks_at(pose_a), landmarks_at(pose_b)
    assert len(la) >= 3
    ids = np.arange(100, 100 + len(la))
    prev = Tracked.fresh(la.surfaces, la.kinds, ids)
    got = recognise(
        prev, lb.surfaces, lb.kinds, motion_step(step_rep, "exact"), max_angle=MAX_ANGLE, max_distance=MAX_DISTANCE
    )
    # Ground truth from the world: the same physical stable endpoint (within the beam spacing
    # at range) on a surface whose sampled direction agrees within the 5 degrees.
    wa, wb = to_world(pose_a, la.surfaces), to_world(pose_b, lb.surfaces)
    expected = {}
    for j in range(len(lb)):
        for i in range(len(la)):
            da, db = wa[i, 1] - wa[i, 0], wb[j, 1] - wb[j, 0]
            turn = abs(se2.wrap(math.atan2(db[1], db[0]) - math.atan2(da[1], da[0])))
            for s in (0, 1):
                stable = la.kinds[i, s] in (OCCLUDING, CORNER) and lb.kinds[j, s] in (OCCLUDING, CORNER)
                if stable and turn < MAX_ANGLE and np.linalg.norm(wa[i, s] - wb[j, s]) < 0.15:
                    expected[j] = ids[i]
    assert len(expected) >= 3
    got_map = {int(np.flatnonzero((lb.surfaces == s).all(axis=1))[0]): int(i) for s, i in zip(got.surfaces, got.ids)}
    assert got_map == expected
    if motion[:2] == (0.0, 0.0):
        # Turning on the spot by whole beams: the beams hit the same world points, so every
        # landmark is found again, exactly.
        assert len(got) == len(la) == len(lb)
        np.testing.assert_allclose(got.gap, 0.0, atol=1e-9)


def test_direction_test_rejects_a_surface_turned_by_more_than_5_degrees() -> None:
    prev = Tracked.fresh(np.array([[0.0, 2.0, 1.0, 2.0]]), np.array([[OCCLUDING, UNSTABLE]]), np.array([7]))
    turned = np.array([[0.0, 2.0, math.cos(math.radians(6)), 2.0 + math.sin(math.radians(6))]])
    slight = np.array([[0.0, 2.0, math.cos(math.radians(4)), 2.0 + math.sin(math.radians(4))]])
    kinds = np.array([[OCCLUDING, UNSTABLE]])
    none = recognise(prev, turned, kinds, (0.0, 0.0, 0.0), max_angle=MAX_ANGLE, max_distance=MAX_DISTANCE)
    one = recognise(prev, slight, kinds, (0.0, 0.0, 0.0), max_angle=MAX_ANGLE, max_distance=MAX_DISTANCE)
    assert len(none) == 0 and one.ids.tolist() == [7]


def test_distance_test_needs_a_same_side_endpoint_stable_in_both_views() -> None:
    prev = Tracked.fresh(np.array([[0.0, 2.0, 1.0, 2.0]]), np.array([[UNSTABLE, OCCLUDING]]), np.array([7]))
    cur = np.array([[0.0, 2.0, 1.0, 2.0]])
    assert (
        len(
            recognise(
                prev,
                cur,
                np.array([[OCCLUDING, UNSTABLE]]),
                (0.0, 0.0, 0.0),
                max_angle=MAX_ANGLE,
                max_distance=MAX_DISTANCE,
            )
        )
        == 0
    )
    far = np.array([[0.0, 2.0, 1.45, 2.0]])
    assert (
        len(
            recognise(
                prev,
                far,
                np.array([[UNSTABLE, CORNER]]),
                (0.0, 0.0, 0.0),
                max_angle=MAX_ANGLE,
                max_distance=MAX_DISTANCE,
            )
        )
        == 0
    )
    near = np.array([[0.0, 2.0, 1.3, 2.0]])
    got = recognise(
        prev, near, np.array([[UNSTABLE, CORNER]]), (0.0, 0.0, 0.0), max_angle=MAX_ANGLE, max_distance=MAX_DISTANCE
    )
    assert got.ids.tolist() == [7] and got.side.tolist() == [1]
    assert got.gap[0] == pytest.approx(0.3) and got.prev_distance[0] == pytest.approx(math.hypot(1.0, 2.0))


def test_greedy_matching_is_one_to_one_and_the_nested_loop_is_literal() -> None:
    kinds = np.array([[OCCLUDING, UNSTABLE]] * 2)
    prev = Tracked.fresh(np.array([[0.0, 2.0, 1.0, 2.0], [0.1, 2.0, 1.1, 2.0]]), kinds, np.array([1, 2]))
    cur = np.array([[0.12, 2.0, 1.1, 2.0], [0.3, 2.0, 1.3, 2.0]])
    greedy = recognise(prev, cur, kinds, (0.0, 0.0, 0.0), max_angle=MAX_ANGLE, max_distance=MAX_DISTANCE)
    nested = recognise(
        prev, cur, kinds, (0.0, 0.0, 0.0), max_angle=MAX_ANGLE, max_distance=MAX_DISTANCE, matching="nested_loop"
    )
    # Greedy: cur0 takes prev 2 (gap 0.02), then cur1 gets prev 1 (0.3; prev 2 is used).
    assert greedy.ids.tolist() == [2, 1]
    # Nested loop: the last passing previous landmark (id 2) labels both.
    assert nested.ids.tolist() == [2, 2]


def test_empty_inputs_recognise_nothing() -> None:
    empty = Tracked.fresh(np.empty((0, 4)), np.empty((0, 2), dtype=np.int64), np.empty(0, dtype=np.int64))
    got = recognise(
        empty,
        np.array([[0.0, 1.0, 1.0, 1.0]]),
        np.array([[1, 1]]),
        (0.0, 0.0, 0.0),
        max_angle=MAX_ANGLE,
        max_distance=MAX_DISTANCE,
    )
    assert len(got) == 0


def test_thesis_frame_pose_conversion() -> None:
    assert rep_to_thesis_pose(np.array([1.0, 2.0, 0.3])) == (-2.0, 1.0, 0.3)


@pytest.mark.parametrize("accelerate", [True, False])
def test_both_recognition_thresholds_are_strict(accelerate: bool) -> None:
    # Algorithm 1 lines 6-7: "angle (S'_i, S_j) < 5 deg" and "occluding/corner point distance (S'_i, S_j) < 40 cm".
    # A pair exactly at either bound is not the same landmark; the next float inside it is.
    kernels = PerceptionKernels(accelerate)
    kinds = np.array([[OCCLUDING, UNSTABLE]])
    prev = Tracked.fresh(np.array([[0.0, 2.0, 1.0, 2.0]]), kinds, np.array([7]))

    def ids(cur: np.ndarray, max_angle: float, max_distance: float) -> list[int]:
        got = recognise(
            prev, cur, kinds, (0.0, 0.0, 0.0), max_angle=max_angle, max_distance=max_distance, kernels=kernels
        )
        return got.ids.tolist()

    moved = np.array([[0.4, 2.0, 1.4, 2.0]])  # P1 exactly 0.4 m from its prediction, same direction
    assert ids(moved, MAX_ANGLE, 0.4) == []
    assert ids(moved, MAX_ANGLE, np.nextafter(0.4, 1.0)) == [7]
    five = math.radians(5.0)
    turned = np.array([[0.0, 2.0, math.cos(five), 2.0 + math.sin(five)]])  # same P1, turned by 5 degrees
    # The angle to the last bit as the kernel measures it (directions P1 -> P2, the difference wrapped): 5 degrees
    # up to rounding, so the bound is set to it rather than to radians(5).
    angle = abs(se2.wrap_angle(math.atan2(math.sin(five) + 2.0 - 2.0, math.cos(five)) - math.atan2(0.0, 1.0)))
    assert angle == pytest.approx(five, rel=1e-12)
    assert ids(turned, angle, MAX_DISTANCE) == []
    assert ids(turned, np.nextafter(angle, 1.0), MAX_DISTANCE) == [7]
