"""View construction and endpoint labels (thesis 3.1.3-3.1.4) on ray-cast geometry with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.synthetic.lidar import cast
from albot1.methods.albot1.perception.endpoints import is_stable
from albot1.methods.albot1.perception.kernels import PerceptionKernels
from albot1.methods.albot1.perception.landmarks import (
    CORNER,
    OCCLUDED,
    OCCLUDING,
    UNSTABLE,
    find_landmarks,
    stable,
)
from albot1.methods.albot1.perception.view import View, ViewParams, construct_view

ANGLES = np.radians(np.arange(-90.0, 91.0, 1.0))

# REP-103 world, robot at the origin facing +x. An L: right wall y = -3 meeting a
# front wall x = 3 at (3, -3) (hit exactly by the -45 degree beam); the front
# wall's left end (3, 1) stands in front of a far wall x = 6.
L_WALLS = np.array(
    [
        [-1.0, -3.0, 3.0, -3.0],
        [3.0, -3.0, 3.0, 1.0],
        [6.0, -3.0, 6.0, 7.0],
    ]
)


def l_view(**params: float):
    ranges = cast(L_WALLS, np.zeros(3), ANGLES, 30.0)
    return construct_view(ranges, ANGLES, ViewParams(**params))


def test_l_corridor_gives_the_corner_landmark_at_the_known_point() -> None:
    view = l_view()
    # Thesis frame: REP (x, y) -> (-y, x); left to right = far wall, front wall, right wall.
    assert len(view) == 3
    far, front, right = view.surfaces
    corner = np.array([3.0, 3.0])  # REP (3, -3)
    np.testing.assert_allclose(front[2:], corner, atol=1e-9)
    np.testing.assert_allclose(right[:2], corner, atol=1e-9)
    assert view.kinds[1, 1] == CORNER and view.kinds[2, 0] == CORNER
    # The front wall's left end is the last beam (18 deg) on it.
    np.testing.assert_allclose(front[:2], [-3.0 * math.tan(math.radians(18.0)), 3.0], atol=1e-9)
    landmarks = find_landmarks(view, 0.4)
    assert landmarks.index.tolist() == [1, 2]
    np.testing.assert_allclose(landmarks.surfaces[1, :2], corner, atol=1e-9)


def test_occluding_and_occluded_ends_and_field_of_view_edges() -> None:
    view = l_view()
    assert view.kinds.tolist() == [
        [UNSTABLE, OCCLUDED],  # far wall: open space to the left up to the edge; hidden by the front wall
        [OCCLUDING, CORNER],  # front wall: in front of the far wall; the corner
        [CORNER, UNSTABLE],  # right wall: the corner; runs out of the field of view
    ]
    assert view.beams.tolist() == [[41, 71], [72, 135], [135, 180]]


def test_surfaces_are_ordered_left_to_right_in_the_thesis_frame() -> None:
    view = l_view()
    bearings = np.degrees(np.arctan2(view.surfaces[:, 0], view.surfaces[:, 1]))
    # Clockwise from the left: bearing (x over y) increases from left to right.
    assert np.all(np.diff(bearings) > 0)
    assert np.all(view.surfaces[:, 0] <= view.surfaces[:, 2])


def test_grazing_gap_along_one_wall_is_not_an_occluding_edge() -> None:
    # A wall 1 m to the left: at a grazing angle consecutive points are > 0.6 m apart.
    ranges = cast(np.array([[0.5, 1.0, 30.0, 1.0]]), np.zeros(3), ANGLES, 30.0)
    view = construct_view(ranges, ANGLES, ViewParams())
    # Beyond ~5.7 m ahead the wall breaks into single points (filtered); the surface's far
    # end has a farther return next to it, but on its own line: not an edge.
    assert len(view) == 1
    np.testing.assert_allclose(view.surfaces[0, [0, 2]], [-1.0, -1.0], atol=1e-9)
    assert view.kinds[0, 1] == UNSTABLE
    literal = construct_view(ranges, ANGLES, ViewParams(continuation_tolerance=0.0))
    assert literal.kinds[0, 1] == OCCLUDING


def test_filtering_clustering_and_surface_length() -> None:
    ranges = np.full(ANGLES.shape, np.nan)
    ranges[80:101] = 2.0  # an arc of 21 beams at 2 m (ahead)
    ranges[10] = 40.0  # beyond max_range: dropped
    ranges[30] = 1.0  # a single point: a zero-length surface, filtered
    view = construct_view(ranges, ANGLES, ViewParams())
    assert len(view) >= 1
    assert np.all(view.lengths >= 0.1)
    assert np.all(np.hypot(view.surfaces[:, 0::2], view.surfaces[:, 1::2]) <= 30.0)
    # The arc's chord is 0.70 m and its sagitta 3 cm < 10 cm: one surface, not split.
    assert len(view) == 1
    np.testing.assert_allclose(view.lengths[0], 2 * 2.0 * math.sin(math.radians(10.0)), atol=1e-9)
    # Left: no return up to the edge of the field of view; right: the 1 m point is nearer.
    assert view.kinds[0].tolist() == [UNSTABLE, OCCLUDED]


def test_short_clusters_are_not_split() -> None:
    ranges = np.full(ANGLES.shape, np.nan)
    ranges[88:93] = [1.0, 1.0, 0.9, 1.0, 1.0]  # a 7 cm chord with a 10 cm dent: under cluster_size
    view = construct_view(ranges, ANGLES, ViewParams(surface_length=0.0))
    assert len(view) == 1
    split = construct_view(ranges, ANGLES, ViewParams(surface_length=0.0, cluster_size=0.0, break_point_height=0.05))
    assert len(split) == 2
    np.testing.assert_allclose(split.surfaces[0, 2:], split.surfaces[1, :2])


def test_scan_with_no_returns_gives_an_empty_view() -> None:
    view = construct_view(np.full(ANGLES.shape, np.nan), ANGLES, ViewParams())
    assert len(view) == 0 and view.surfaces.shape == (0, 4)
    assert len(find_landmarks(view, 0.4)) == 0


def test_only_occluding_and_corner_endpoints_are_stable_in_both_forms() -> None:
    kinds = [UNSTABLE, OCCLUDING, CORNER, OCCLUDED]
    assert [is_stable(k) for k in kinds] == [False, True, True, False]
    assert stable(np.array([kinds, kinds[::-1]])).tolist() == [[False, True, True, False], [False, True, True, False]]


# REP-103, robot at the origin facing +x. A wall on the left (y = 1) ends at x = 4, where a doorway opens onto a
# room whose far wall (y = 5) is seen through it. The wall's last lit point is the 15 deg beam's (1/tan 15 deg =
# 3.732 m), not its true end (4 m): the 14 deg beam passes the end and returns from the far wall, which is not on the
# wall's line, so neither the range test nor the continuation test sees anything wrong. The next point inward on the
# wall is the 16 deg beam's, 1/tan 15 deg - 1/tan 16 deg = 0.2446 m away: the beams are sparse there.
GRAZING_WALLS = np.array([[-1.0, 1.0, 4.0, 1.0], [4.0, 5.0, 40.0, 5.0]])
GRAZING_SPACING = 1.0 / math.tan(math.radians(15.0)) - 1.0 / math.tan(math.radians(16.0))


def grazing_view(**params: float):
    ranges = cast(GRAZING_WALLS, np.zeros(3), ANGLES, 30.0)
    view = construct_view(ranges, ANGLES, ViewParams(**params))
    # Thesis frame: the left wall is x = -1; its far (right) end P2 is the 15 deg beam's point.
    wall = int(np.flatnonzero(np.isclose(view.surfaces[:, 0], -1.0) & np.isclose(view.surfaces[:, 2], -1.0))[0])
    return view, wall


def test_grazing_end_through_an_opening_is_unstable_by_beam_spacing() -> None:
    assert GRAZING_SPACING == pytest.approx(0.24464, abs=1e-5)
    bare, wall = grazing_view(end_spacing_max=0.0)
    np.testing.assert_allclose(bare.surfaces[wall, 2:], [-1.0, 1.0 / math.tan(math.radians(15.0))], atol=1e-9)
    assert bare.kinds[wall, 1] == OCCLUDING  # the thesis's test alone calls this moving end an edge
    tested, wall = grazing_view(end_spacing_max=0.2)
    assert tested.kinds[wall, 1] == UNSTABLE
    # The threshold is exact: just above the spacing the end keeps its label.
    kept, wall = grazing_view(end_spacing_max=GRAZING_SPACING + 1e-6)
    assert kept.kinds[wall, 1] == OCCLUDING
    below, wall = grazing_view(end_spacing_max=GRAZING_SPACING - 1e-6)
    assert below.kinds[wall, 1] == UNSTABLE


def test_grazing_factor_spares_far_ends_seen_face_on() -> None:
    # The 15/16 deg beams are 1 deg apart; face-on at the end's range (1/sin 15 deg = 3.864 m) they would be
    # 3.864 * pi/180 = 0.0674 m apart, so the spacing is 3.63 times that: a grazing angle of 74 deg.
    ratio = GRAZING_SPACING / ((1.0 / math.sin(math.radians(15.0))) * math.radians(1.0))
    assert ratio == pytest.approx(3.63, abs=0.01)
    grazing, wall = grazing_view(end_spacing_max=0.2, end_spacing_grazing=ratio - 0.01)
    assert grazing.kinds[wall, 1] == UNSTABLE
    face_on, wall = grazing_view(end_spacing_max=0.2, end_spacing_grazing=ratio + 0.01)
    assert face_on.kinds[wall, 1] == OCCLUDING


def test_beam_spacing_keeps_a_face_on_occluding_end() -> None:
    # The L's front wall (x = 3) has its occluding left end on the 18 deg beam; the next beam on it is 0.055 m away.
    assert l_view(end_spacing_max=0.2).kinds.tolist() == l_view().kinds.tolist()
    assert l_view(end_spacing_max=0.2).kinds[1, 0] == OCCLUDING


def test_total_least_squares_puts_the_corner_at_the_intersection_of_the_walls() -> None:
    # The L with its front wall moved to x = 3.05: the corner (3.05, -3) lies between the -44 and -45 deg beams,
    # so the chords' shared split point is a beam's point on one wall, off the corner; the fitted lines cross on it.
    walls = L_WALLS + np.array([[0.0, 0.0, 0.05, 0.0], [0.05, 0.0, 0.05, 0.0], [0.0, 0.0, 0.0, 0.0]])
    ranges = cast(walls, np.zeros(3), ANGLES, 30.0)
    chord = construct_view(ranges, ANGLES, ViewParams())
    fitted = construct_view(ranges, ANGLES, ViewParams(fit_lines=True))
    corner = np.array([3.0, 3.05])  # REP (3.05, -3) in the thesis frame
    assert fitted.kinds.tolist() == chord.kinds.tolist() and fitted.beams.tolist() == chord.beams.tolist()
    assert chord.kinds[1, 1] == CORNER
    np.testing.assert_array_equal(fitted.surfaces[1, 2:], fitted.surfaces[2, :2])
    np.testing.assert_allclose(fitted.surfaces[1, 2:], corner, atol=1e-9)
    # The split point is the -44 deg beam's hit on the front wall, 3.05 (1 - tan 44 deg) = 5.5 cm from the corner.
    np.testing.assert_allclose(chord.surfaces[1, 2:], [3.05 * math.tan(math.radians(44.0)), 3.05], atol=1e-9)


def test_total_least_squares_averages_range_noise_out_of_a_wall_direction() -> None:
    """Over 20 noisy scans the front wall's direction error is several times smaller fitted than as a chord."""
    rng = np.random.default_rng(0)
    exact = cast(L_WALLS, np.zeros(3), ANGLES, 30.0)

    def direction_error(s: np.ndarray) -> float:
        return abs(math.degrees(math.atan2(s[3] - s[1], s[2] - s[0])))  # the front wall runs along thesis +x

    chord_err, fitted_err = [], []
    for _ in range(20):
        ranges = exact + rng.normal(0.0, 0.01, ANGLES.size)
        chord_err.append(direction_error(construct_view(ranges, ANGLES, ViewParams()).surfaces[1]))
        fitted_err.append(direction_error(construct_view(ranges, ANGLES, ViewParams(fit_lines=True)).surfaces[1]))
    assert np.mean(fitted_err) < 0.5 * np.mean(chord_err)


def test_total_least_squares_is_exact_on_exact_points() -> None:
    ranges = cast(L_WALLS, np.zeros(3), ANGLES, 30.0)
    chord = construct_view(ranges, ANGLES, ViewParams())
    fitted = construct_view(ranges, ANGLES, ViewParams(fit_lines=True))
    np.testing.assert_allclose(fitted.surfaces, chord.surfaces, atol=1e-9)


@pytest.mark.parametrize("accelerate", [True, False])
def test_a_landmark_is_at_least_40_cm_long_with_an_occluding_or_corner_end(accelerate: bool) -> None:
    # Thesis 3.1.4: "surfaces with a minimum length of 40cm and which has at least one occluding or corner edge are
    # considered as landmark surfaces". Exactly 40 cm is a landmark, the next float below is not; a corner end alone
    # suffices (3.1.4 names corners; Algorithm 4 line 4 and section 3.1 name occluding edges only: the code reads
    # 3.1.4, docs/albot1-mapper.md item 9); occluded and unstable ends do not.
    surfaces = np.array(
        [
            [0.0, 2.0, 0.4, 2.0],  # exactly 0.4 m, occluding P1
            [0.0, 3.0, np.nextafter(0.4, 0.0), 3.0],  # just under 0.4 m, occluding P1
            [0.0, 4.0, 1.0, 4.0],  # corner P2 only
            [0.0, 5.0, 1.0, 5.0],  # occluded and unstable ends
            [0.0, 6.0, 2.0, 6.0],  # occluding P2
        ]
    )
    kinds = np.array(
        [[OCCLUDING, UNSTABLE], [OCCLUDING, UNSTABLE], [UNSTABLE, CORNER], [OCCLUDED, UNSTABLE], [UNSTABLE, OCCLUDING]]
    )
    view = View(surfaces, kinds, np.zeros((5, 2), dtype=np.int64), np.arange(5, dtype=np.int64))
    got = find_landmarks(view, 0.4, PerceptionKernels(accelerate))
    assert got.index.tolist() == [0, 2, 4]
    np.testing.assert_array_equal(got.surfaces, surfaces[[0, 2, 4]])
    np.testing.assert_array_equal(got.kinds, kinds[[0, 2, 4]])


# A 360-degree scanner (a TurtleBot's LDS-01: 360 beams, 1 deg apart, beam 0 straight ahead): three separate
# walls, one across the seam straight ahead (x = 3 from y = -1 to 1), one to the left (y = 4 from x = -2 to 2) and
# one behind (x = -3 from y = -1.5 to 1.5).
FULL_TURN_WALLS = np.array([[3.0, -1.0, 3.0, 1.0], [-2.0, 4.0, 2.0, 4.0], [-3.0, -1.5, -3.0, 1.5]])


@pytest.mark.parametrize("first_deg", [0.0, -90.0, -180.0, 45.0])
def test_full_turn_view_does_not_depend_on_where_the_beams_begin(first_deg: float) -> None:
    # Each wall is one surface whatever beam the scanner starts from; a scan starting straight ahead (as the
    # LDS-01 does) used to cut the wall ahead in two at its first beam, with two unstable "field of view" ends.
    angles = np.radians(first_deg + np.arange(360.0))
    ranges = cast(FULL_TURN_WALLS, np.zeros(3), angles, 30.0)
    view = construct_view(ranges, angles, ViewParams())
    assert len(view) == 3
    rep = np.column_stack([view.surfaces[:, 1], -view.surfaces[:, 0], view.surfaces[:, 3], -view.surfaces[:, 2]])
    ends = sorted(tuple(np.sort(row.reshape(2, 2), axis=0).ravel()) for row in rep)
    # each surface runs between the hits of the outermost whole-degree beams on its wall: -18..18 deg on the wall
    # ahead (its ends at +-18.4 deg), 64..116 deg on the left one, 154..206 deg on the one behind
    t = math.tan
    expected = [
        (-3.0, -3.0 * t(math.radians(26.0)), -3.0, 3.0 * t(math.radians(26.0))),
        (-4.0 / t(math.radians(64.0)), 4.0, 4.0 / t(math.radians(64.0)), 4.0),
        (3.0, -3.0 * t(math.radians(18.0)), 3.0, 3.0 * t(math.radians(18.0))),
    ]
    np.testing.assert_allclose(ends, expected, rtol=0, atol=1e-9)
    # Albot1+'s fused call (view, landmarks and points in one kernel) moves the seam the same way
    from albot1.methods.albot1.mapping.step_kernels import perceive_scan

    fused, _, _ = perceive_scan(ranges, angles, ViewParams(), 0.4, 30.0, 0)
    np.testing.assert_array_equal(fused.surfaces, view.surfaces)
    np.testing.assert_array_equal(fused.kinds, view.kinds)


def test_seam_moves_only_for_a_full_turn() -> None:
    from albot1.methods.albot1.perception.view import seam_at_gap

    angles = np.radians(np.arange(360.0))
    ranges = cast(FULL_TURN_WALLS, np.zeros(3), angles, 30.0)
    r, a = seam_at_gap(ranges, angles, 30.0)
    assert np.all(np.diff(a) > 0) and a[-1] - a[0] == pytest.approx(np.radians(359.0))
    # the widest gap between returns lies between the back wall and the wall ahead, or the wall on the left
    assert set(np.round(np.degrees(a[[0, -1]]) % 360.0)) != {0.0, 359.0}
    np.testing.assert_array_equal(np.sort(r[np.isfinite(r)]), np.sort(ranges[np.isfinite(ranges)]))
    half = np.radians(np.arange(-135.0, 135.25, 0.25))  # 270 deg: its own edges, never moved
    r2, a2 = seam_at_gap(cast(FULL_TURN_WALLS, np.zeros(3), half, 30.0), half, 30.0)
    assert a2 is half
