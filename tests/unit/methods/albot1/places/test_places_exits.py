"""Exits: the detector on hand-made views, the tracker, and the crossing test (thesis 4.1.1)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.methods.albot1.perception.endpoints import CORNER, OCCLUDED, OCCLUDING, UNSTABLE
from albot1.methods.albot1.perception.view import View
from albot1.methods.albot1.places.config import Albot1PlacesConfig, ExitParams
from albot1.methods.albot1.places.exits import ExitTracker, orient_left, view_exits
from albot1.methods.albot1.places.kernels import PlacesKernels

KERNELS = [PlacesKernels(False), PlacesKernels(True)]
PARAMS = ExitParams()


def view(surfaces: list[list[float]], kinds: list[tuple[int, int]]) -> View:
    """A view from hand-made surfaces (thesis frame, left to right)."""
    s = np.asarray(surfaces, dtype=float).reshape(-1, 4)
    k = np.asarray(kinds, dtype=np.int64).reshape(-1, 2)
    n = len(s)
    return View(s, k, np.zeros((n, 2), dtype=np.int64), np.arange(n, dtype=np.int64))


# A wall 3 m ahead with a 1 m doorway from x = -0.5 to 0.5, the next room's back wall seen through it at 6 m.
DOORWAY = view(
    [[-3.0, 3.0, -0.5, 3.0], [-0.4, 6.0, 0.4, 6.0], [0.5, 3.0, 3.0, 3.0]],
    [(UNSTABLE, OCCLUDING), (OCCLUDED, OCCLUDED), (OCCLUDING, UNSTABLE)],
)


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_doorway_between_occluding_ends_is_an_exit(kernels) -> None:
    exits = view_exits(DOORWAY, PARAMS, kernels)
    np.testing.assert_allclose(exits, [[-0.5, 3.0, 0.5, 3.0]])


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_gaps_that_are_not_exits(kernels) -> None:
    def found(surfaces: list[list[float]], kinds: list[tuple[int, int]]) -> int:
        return len(view_exits(view(surfaces, kinds), PARAMS, kernels))

    # a desk in front of the wall: its end occludes, but the wall behind it starts at an occluded end
    assert found([[-1.5, 2.0, -0.5, 2.0], [0.3, 3.0, 2.0, 3.0]], [(CORNER, OCCLUDING), (OCCLUDED, UNSTABLE)]) == 0
    # too wide (a corridor opening of 2 m) and too narrow (0.4 m)
    wide = [[-3.0, 3.0, -1.0, 3.0], [1.0, 3.0, 3.0, 3.0]]
    narrow = [[-3.0, 3.0, -0.2, 3.0], [0.2, 3.0, 3.0, 3.0]]
    assert found(wide, [(UNSTABLE, OCCLUDING), (OCCLUDING, UNSTABLE)]) == 0
    assert found(narrow, [(UNSTABLE, OCCLUDING), (OCCLUDING, UNSTABLE)]) == 0
    # a shallow recess: what is seen through the gap lies only 0.3 m behind it
    recess = [[-3.0, 3.0, -0.5, 3.0], [-0.4, 3.3, 0.4, 3.3], [0.5, 3.0, 3.0, 3.0]]
    assert found(recess, [(UNSTABLE, OCCLUDING), (OCCLUDED, OCCLUDED), (OCCLUDING, UNSTABLE)]) == 0
    # too far from the robot
    far = [[-3.0, 8.0, -0.5, 8.0], [0.5, 8.0, 3.0, 8.0]]
    assert found(far, [(UNSTABLE, OCCLUDING), (OCCLUDING, UNSTABLE)]) == 0


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_one_occluding_end_is_enough_only_when_configured(kernels) -> None:
    v = view([[-3.0, 3.0, -0.5, 3.0], [0.5, 3.0, 3.0, 3.0]], [(UNSTABLE, OCCLUDING), (CORNER, UNSTABLE)])
    assert len(view_exits(v, PARAMS, kernels)) == 0
    relaxed = Albot1PlacesConfig(exit_endpoints="one_occluding").exit_params()
    assert len(view_exits(v, relaxed, kernels)) == 1


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_each_end_takes_part_in_one_exit_the_narrowest(kernels) -> None:
    # two candidate right ends for the same left end: 0.8 m and 1.1 m away
    v = view(
        [[-3.0, 3.0, -0.4, 3.0], [0.4, 3.0, 0.6, 3.0], [0.7, 3.0, 3.0, 3.0]],
        [(UNSTABLE, OCCLUDING), (OCCLUDING, OCCLUDING), (OCCLUDING, UNSTABLE)],
    )
    np.testing.assert_allclose(view_exits(v, PARAMS, kernels), [[-0.4, 3.0, 0.4, 3.0]])


def test_the_config_reads_into_the_params_and_refuses_crossed_widths() -> None:
    cfg = Albot1PlacesConfig()
    p = cfg.exit_params()
    assert (p.min_width, p.max_width, p.min_sightings, p.both_occluding) == (0.6, 1.2, 3, True)
    assert p.track_angle == pytest.approx(math.radians(20.0))
    with pytest.raises(ValueError, match="exit_min_width_m"):
        Albot1PlacesConfig(exit_min_width_m=1.5, exit_max_width_m=1.0)


def tracker_with_doorway(kernels) -> ExitTracker:
    """A tracker that has seen the doorway (wall along y = 3, gap x -0.5..0.5) from (0, 0) three times."""
    tracker = ExitTracker(PARAMS, kernels)
    for scan in range(3):
        tracker.observe(DOORWAY, (0.0, 0.0, 0.0), scan)
        assert tracker.crossing((0.0, 0.0), scan) is None
    assert tracker.confirmed == 1
    return tracker


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_walking_through_the_doorway_is_one_crossing(kernels) -> None:
    tracker = tracker_with_doorway(kernels)
    ys = np.arange(1.0, 5.0, 0.1)
    crossings = [(k, tracker.crossing((0.05, y), 3 + k)) for k, y in enumerate(ys)]
    found = [(k, c) for k, c in crossings if c is not None]
    assert len(found) == 1
    k, c = found[0]
    # reported at the first position clearly beyond the line (hysteresis band), not before
    assert ys[k] - 3.0 > PARAMS.crossing_band >= ys[k - 1] - 3.0
    # the segment runs with the side left behind (y < 3) on its left
    a, b = c.segment[:2], c.segment[2:]
    assert (b[0] - a[0]) * (1.0 - a[1]) - (b[1] - a[1]) * (0.0 - a[0]) > 0


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_jitter_on_the_threshold_and_walking_past_the_wall_are_not_crossings(kernels) -> None:
    tracker = tracker_with_doorway(kernels)
    # back and forth within the band around the exit line
    for k, y in enumerate([2.9, 3.1, 2.85, 3.15, 2.95, 3.05]):
        assert tracker.crossing((0.0, y), 10 + k) is None
    # leaving the band on the side it came from
    assert tracker.crossing((0.0, 2.5), 20) is None
    # going round the end of the wall (x = 4) to the far side is no crossing of the doorway
    for k, (x, y) in enumerate([(4.0, 2.5), (4.0, 3.5), (0.0, 3.5)]):
        assert tracker.crossing((x, y), 30 + k) is None


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_an_old_track_of_the_same_doorway_is_not_crossed_twice(kernels) -> None:
    tracker = tracker_with_doorway(kernels)
    # the same doorway re-detected 0.6 m farther on (the map drifted): a second track, a twin of the first
    shifted = view(
        [[-3.0, 3.6, -0.5, 3.6], [-0.4, 6.6, 0.4, 6.6], [0.5, 3.6, 3.0, 3.6]],
        [(UNSTABLE, OCCLUDING), (OCCLUDED, OCCLUDED), (OCCLUDING, UNSTABLE)],
    )
    for scan in range(3, 6):
        tracker.observe(shifted, (0.0, 0.0, 0.0), scan)
        tracker.crossing((0.0, 0.0), scan)
    assert tracker.confirmed == 2
    found = [tracker.crossing((0.0, y), 10 + k) for k, y in enumerate(np.arange(1.0, 6.0, 0.1))]
    assert sum(c is not None for c in found) == 1


def test_orient_left_puts_the_given_point_on_the_left() -> None:
    seg = np.array([0.0, 0.0, 1.0, 0.0])
    np.testing.assert_allclose(orient_left(seg, (0.5, 1.0)), seg)
    np.testing.assert_allclose(orient_left(seg, (0.5, -1.0)), [1.0, 0.0, 0.0, 0.0])


def test_points_seen_through_an_exit_and_standing_in_a_doorway() -> None:
    tracker = tracker_with_doorway(KERNELS[0])
    through = tracker.beyond((0.0, 0.0), np.array([[0.0, 6.0], [2.0, 2.0], [2.0, 6.0]]), 3)
    assert through[0] >= 0 and through[1] == -1 and through[2] == -1
    assert tracker.near((0.1, 2.8), 0.5, 3) and not tracker.near((0.0, 1.0), 0.5, 3)
    # not seen for longer than exit_recent_scans: no longer decides either
    assert (tracker.beyond((0.0, 0.0), np.array([[0.0, 6.0]]), 500) == -1).all()
