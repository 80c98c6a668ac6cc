"""The thesis's own measures against answers worked out here by hand (plain numpy and shapely, not the helpers).

Loop gap, Table 3.1's bearing and distance of the start, updates per view, map shape and drift, on small
inputs with exact answers: a square loop with a known gap, a rotated estimate, headings either side of
+-180 deg, a map a known distance off its walls, one pose, no views, NaN poses.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import MultiPoint, Point

from albot1.metrics.drift import drift
from albot1.metrics.errors import MetricsError
from albot1.metrics.loop_gap import route_gap
from albot1.metrics.map_shape import map_agreement
from albot1.metrics.orientation import orientation_table
from albot1.metrics.updates import update_counts


def square(side: float = 10.0, step: float = 0.5) -> np.ndarray:
    """A closed square loop driven anticlockwise from the origin, heading along each side."""
    poses = []
    for k, heading in enumerate((0.0, math.pi / 2, -math.pi, -math.pi / 2)):
        corner = [(0, 0), (side, 0), (side, side), (0, side)][k]
        for s in np.arange(0.0, side, step):
            poses.append((corner[0] + s * math.cos(heading), corner[1] + s * math.sin(heading), heading))
    poses.append((0.0, 0.0, 0.0))
    return np.array(poses)


def moved(poses: np.ndarray, x: float, y: float, angle: float) -> np.ndarray:
    """``poses`` under the rigid motion (x, y, angle): the same trajectory in another frame."""
    c, s = math.cos(angle), math.sin(angle)
    out = np.column_stack([c * poses[:, 0] - s * poses[:, 1] + x, s * poses[:, 0] + c * poses[:, 1] + y, poses[:, 2]])
    out[:, 2] = np.angle(np.exp(1j * (poses[:, 2] + angle)))
    return out


def end_seen_from_start(p: np.ndarray) -> np.ndarray:
    c, s = math.cos(p[0, 2]), math.sin(p[0, 2])
    d = p[-1, :2] - p[0, :2]
    return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])


def test_square_loop_gap_is_the_end_offset_in_any_frame() -> None:
    ref = square()
    est = ref.copy()
    est[-1, :2] += (0.6, -0.8)  # the estimate ends 1.0 m from its start
    est = moved(est, 3.0, -7.0, 2.5)  # and lives in another frame: the gap must not change
    expected = float(np.linalg.norm(end_seen_from_start(est) - end_seen_from_start(ref)))
    assert expected == pytest.approx(1.0)
    gap = route_gap(est, ref)
    assert gap["gap_m"] == pytest.approx(1.0) and gap["reference_offset_m"] == pytest.approx(0.0, abs=1e-12)
    assert route_gap(est, None)["gap_m"] == pytest.approx(1.0)  # the closed route's form: end-to-start distance


def test_heading_gap_wraps_at_180_deg() -> None:
    est = np.array([[0.0, 0.0, math.radians(179.0)], [1.0, 0.0, math.radians(-179.0)]])
    ref = np.array([[0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    assert route_gap(est, ref)["heading_gap_deg"] == pytest.approx(2.0)


@pytest.mark.parametrize("reference", [True, False])
def test_a_nan_pose_is_refused_with_its_scan(reference: bool) -> None:
    est = square()
    est[-1, 2] = math.nan
    with pytest.raises(MetricsError, match=r"^loop gap: the estimate has a non-finite pose at scan 80$"):
        route_gap(est, square() if reference else None)


def test_one_pose_has_no_loop_gap_nor_stops_nor_drift() -> None:
    one = np.zeros((1, 3))
    with pytest.raises(MetricsError, match="at least 2 poses"):
        route_gap(one)
    table = orientation_table(one, one)
    assert table["stops"] == 0 and table["bearing_abs_error_max_deg"] is None
    block = drift(one, one)
    assert (
        block["at_10m"] is None
        and block["at_10m_reason"] == "the route (0.0 m of reference travel) has no 10 m segment"
    )


def test_table_3_1_bearing_and_distance_by_hand_across_180_deg() -> None:
    # Both robots face +x at x = 20 with the start (the origin) behind them, the estimate just left of the
    # line and the reference just right: bearings +179.9 and -179.9 deg, -0.2 deg apart through 180, not 359.8.
    dy = 20.0 * math.tan(math.radians(0.1))
    est = np.array([[0.0, 0.0, 0.0], [20.0, -dy, 0.0]])
    ref = np.array([[0.0, 0.0, 0.0], [20.0, dy, 0.0]])
    row = orientation_table(est, ref, every_m=100.0)["rows"][0]
    assert row["estimate_bearing_deg"] == pytest.approx(179.9)
    assert row["reference_bearing_deg"] == pytest.approx(-179.9)
    assert row["bearing_error_deg"] == pytest.approx(-0.2)
    assert row["distance_error_m"] == pytest.approx(0.0, abs=1e-12)
    # a turn to the left is + (the thesis's sign): facing +y at (10, 0), the start (-x) is on the left, +90 deg
    left = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, math.pi / 2]])
    assert orientation_table(left, left, every_m=100.0)["rows"][0]["reference_bearing_deg"] == pytest.approx(90.0)


def test_updates_per_view() -> None:
    assert update_counts({"views": 1330, "updates": 470})["updates_per_view"] == pytest.approx(470 / 1330)
    assert update_counts({"views": 0, "updates": 0})["updates_per_view"] is None  # n/a, not 0


def test_map_shape_of_a_map_a_known_distance_off_its_walls() -> None:
    xs = np.arange(0.05, 10.0, 0.1)  # one point per 0.1 m thinning cell: 100 per wall, none thinned away
    walls = np.concatenate([np.column_stack([xs, np.zeros_like(xs)]), np.column_stack([xs, np.full_like(xs, 4.0)])])
    cloud = MultiPoint([tuple(p) for p in walls])
    for offset, inside in ((0.2, 1.0), (0.35, 0.0)):
        drawn = walls + (0.0, offset)
        by_hand = np.array([cloud.distance(Point(p)) for p in drawn])
        block = map_agreement(drawn, walls)
        assert block["map_to_reference_median_m"] == pytest.approx(float(np.median(by_hand)))
        assert block["map_to_reference_median_m"] == pytest.approx(offset)
        assert block["precision"] == inside and block["coverage"] == inside
    one = map_agreement(np.array([[5.0, 0.1]]), walls)  # one point: precise, covers 6 of the 200 wall points
    near = [Point(p).distance(Point(5.0, 0.1)) <= 0.3 for p in walls]
    assert (one["precision"], one["map_points"], one["reference_points"]) == (1.0, 1, 200)
    assert one["coverage"] == pytest.approx(float(np.mean(near))) == 6 / 200
    with pytest.raises(MetricsError, match="the method's map has no geometry to compare"):
        map_agreement(np.empty((0, 2)), walls)


def test_drift_of_a_route_that_never_returns() -> None:
    ref = np.column_stack([np.arange(0.0, 30.1, 0.5), np.zeros(61), np.zeros(61)])
    est = ref.copy()
    est[:, 0] *= 1.1  # 10 % too long: 1 m over every 10 m segment
    at_10m = drift(est, ref)["at_10m"]
    assert at_10m["translation_m"] == pytest.approx(1.0) and at_10m["rotation_deg"] == 0.0
    assert at_10m["pairs"] == 21  # starts at 0..20 m
