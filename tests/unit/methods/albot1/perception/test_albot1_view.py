"""View construction and endpoint labels (thesis 3.1.3-3.1.4) on ray-cast geometry with known answers."""

from __future__ import annotations

import math

import numpy as np

from albot1.data.synthetic.lidar import cast
from albot1.methods.albot1.perception.endpoints import is_stable
from albot1.methods.albot1.perception.landmarks import (
    CORNER,
    OCCLUDED,
    OCCLUDING,
    UNSTABLE,
    find_landmarks,
    stable,
)
from albot1.methods.albot1.perception.view import ViewParams, construct_view

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
