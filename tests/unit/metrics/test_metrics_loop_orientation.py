"""Loop gap and the Table-3.1 orientation measure on square routes with exact answers."""

from __future__ import annotations

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.metrics.loop_gap import loop_pairs, pair_gaps, route_gap
from albot1.metrics.orientation import home_vector, orientation_table, stop_indices

SIDE = 10


def square(turn_error_deg: float = 0.0, sides: int = 4) -> np.ndarray:
    """A counter-clockwise square route sampled every metre, written out pose by pose.

    The robot turns at each corner (the corner scan already has the new
    heading); the first turn is wrong by ``turn_error_deg``, all later turns are
    right, so every later side runs off by that angle.
    """
    poses = [[0.0, 0.0, 0.0]]
    x = y = heading = 0.0
    for side in range(sides):
        for step in range(1, SIDE + 1):
            x += np.cos(heading)
            y += np.sin(heading)
            last = step == SIDE
            turn = (np.pi / 2 + (np.radians(turn_error_deg) if side == 0 else 0.0)) if last else 0.0
            poses.append([x, y, heading + turn])
        heading += np.pi / 2 + (np.radians(turn_error_deg) if side == 0 else 0.0)
    out = np.asarray(poses)
    out[:, 2] = se2.wrap(out[:, 2])
    return out


def test_square_reference_is_built_right() -> None:
    ref = square()
    assert len(ref) == 4 * SIDE + 1
    np.testing.assert_allclose(ref[-1, :2], [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(ref[SIDE], [10.0, 0.0, np.pi / 2], atol=1e-12)


def test_route_gap_of_an_end_offset_is_the_offset() -> None:
    ref = square()
    est = ref.copy()
    est[-1, :2] += [0.4, 0.0]  # the thesis's Albot1 value, 0.4 m
    block = route_gap(est, ref)
    assert block["gap_m"] == pytest.approx(0.4)
    assert block["reference_offset_m"] == pytest.approx(0.0, abs=1e-12)
    assert block["estimated_offset_m"] == pytest.approx(0.4)
    # Without a reference but known to be closed: the end-to-start distance.
    assert route_gap(est)["gap_m"] == pytest.approx(0.4)


def test_route_gap_of_a_wrong_first_turn() -> None:
    eps = 5.0
    est, ref = square(eps), square()
    # Three sides of 10 m after a turn wrong by eps: the end misses the start by
    # the rotation of the 3-side path (10, 10) -> ... about the first corner.
    corner = np.array([10.0, 0.0])
    rest = ref[-1, :2] - corner
    c, s = np.cos(np.radians(eps)), np.sin(np.radians(eps))
    end = corner + np.array([c * rest[0] - s * rest[1], s * rest[0] + c * rest[1]])
    block = route_gap(est, ref)
    assert block["gap_m"] == pytest.approx(np.hypot(*end))
    assert block["gap_m"] == pytest.approx(2 * 10.0 * np.sin(np.radians(eps) / 2))
    assert block["heading_gap_deg"] == pytest.approx(eps)


def test_revisit_pairs_find_the_return_to_start() -> None:
    ref = square()
    stamps = np.arange(len(ref)) * 5.0
    pairs = loop_pairs(stamps, ref)
    assert pairs.tolist() == [[0, 40]]  # only the end is within 0.5 m of an earlier pose
    est = ref.copy()
    est[-1, :2] += [0.3, -0.4]
    block = pair_gaps(stamps, est, ref)
    assert block["pairs"] == 1
    assert block["translation_m"]["max"] == pytest.approx(0.5)
    assert block["worst_pair"]["scans"] == [0, 40]


def test_revisits_need_time_and_travel() -> None:
    ref = square()
    assert len(loop_pairs(np.arange(len(ref)) * 0.5, ref)) == 0  # 20 s round trip: not > 30 s
    parked = np.zeros((50, 3))
    assert len(loop_pairs(np.arange(50) * 10.0, parked)) == 0  # standing still is not a loop
    assert len(loop_pairs(np.zeros(50), parked)) == 0  # nor without a clock


def test_a_log_that_stamps_every_scan_alike_has_its_revisits_judged_by_travel_alone() -> None:
    """belgioioso-, freiburg-campus- and orebro-corrected stamp every scan 0: the time bound (0 s apart, not > 30 s)
    dropped every revisit, and the block said "pairs: 0" on routes that return (belgioioso 12 pairs, orebro 11)."""
    ref = square()
    est = ref.copy()
    est[-1, :2] += [0.3, -0.4]
    clocked = pair_gaps(np.arange(len(ref)) * 5.0, est, ref)
    unclocked = pair_gaps(np.zeros(len(ref)), est, ref)
    assert unclocked["pairs"] == 1 and unclocked["translation_m"] is not None
    assert (clocked["pairs"], clocked["pairs_same_stamp"]) == (1, 0)
    assert (unclocked["pairs"], unclocked["pairs_same_stamp"]) == (1, 1)
    assert unclocked["worst_pair"] == clocked["worst_pair"] == {"scans": [0, 40], "gap_m": pytest.approx(0.5)}
    # a clock on part of the log (csail: two stamps for 406 scans): a pair across two stamps keeps the time bound
    two = np.where(np.arange(len(ref)) < 20, 0.0, 10.0)
    assert loop_pairs(two, ref).tolist() == []  # 10 s apart: not > 30 s
    assert loop_pairs(np.where(np.arange(len(ref)) < 20, 0.0, 100.0), ref).tolist() == [[0, 40]]


def test_table_3_1_rows_for_a_wrong_first_turn() -> None:
    eps = 10.0
    est, ref = square(eps, sides=2), square(sides=2)
    table = orientation_table(est, ref, np.arange(len(ref)) * 1.0, every_m=10.0)
    assert [row["scan"] for row in table["rows"]] == [10, 20]
    first, second = table["rows"]
    # Stop 1 at (10, 0) facing +y: the start is straight to the left (+90 deg), 10 m.
    assert first["reference_bearing_deg"] == pytest.approx(90.0)
    assert first["reference_distance_m"] == pytest.approx(10.0)
    # The estimate believes it turned eps too far: start appears eps less to the left.
    assert first["estimate_bearing_deg"] == pytest.approx(90.0 - eps)
    assert first["bearing_error_deg"] == pytest.approx(-eps)
    assert first["distance_error_m"] == pytest.approx(0.0, abs=1e-12)
    # Stop 2 at (10, 10) facing -x: start 45 deg to the left, 10 sqrt 2 m.
    assert second["reference_bearing_deg"] == pytest.approx(45.0)
    assert second["reference_distance_m"] == pytest.approx(10.0 * np.sqrt(2.0))
    e = np.radians(eps)
    est_pos = np.array([10.0 - 10.0 * np.sin(e), 10.0 * np.cos(e)])
    est_heading = np.pi + e
    bearing = np.degrees(se2.wrap(np.arctan2(-est_pos[1], -est_pos[0]) - est_heading))
    assert second["estimate_bearing_deg"] == pytest.approx(bearing)
    assert second["estimate_distance_m"] == pytest.approx(10.0 * np.sqrt(2.0 - 2.0 * np.sin(e)))
    errors = [abs(first["bearing_error_deg"]), abs(second["bearing_error_deg"])]
    assert table["bearing_abs_error_mean_deg"] == pytest.approx(np.mean(errors))
    assert table["bearing_abs_error_max_deg"] == pytest.approx(max(errors))
    expected_distance_error = 10.0 * np.sqrt(2.0) - 10.0 * np.sqrt(2.0 - 2.0 * np.sin(e))
    assert table["distance_abs_error_max_m"] == pytest.approx(expected_distance_error)


def test_bearing_at_the_start_itself_is_left_out() -> None:
    ref = square()
    table = orientation_table(ref, ref, every_m=10.0)
    assert [row["scan"] for row in table["rows"]] == [10, 20, 30, 40]
    assert table["rows"][-1]["bearing_error_deg"] is None  # the final scan is back at the start
    assert table["bearing_undefined"] == 1
    assert table["bearing_abs_error_max_deg"] == pytest.approx(0.0, abs=1e-9)


def test_right_turn_has_negative_bearing() -> None:
    poses = np.array([[0.0, 0.0, 0.0], [5.0, 0.0, np.pi / 2 + np.pi / 4]])
    bearing, distance = home_vector(poses, 1)
    # Facing 135 deg, the start lies at 180 deg: 45 deg to the left.
    assert (bearing, distance) == (pytest.approx(45.0), pytest.approx(5.0))
    poses[1, 2] = np.pi + np.pi / 4  # facing 225 deg: the start is 45 deg to the right
    assert home_vector(poses, 1)[0] == pytest.approx(-45.0)


def test_stops_every_n_metres_plus_the_last_scan() -> None:
    ref = np.column_stack([np.arange(26, dtype=float), np.zeros(26), np.zeros(26)])
    assert stop_indices(ref, 10.0).tolist() == [10, 20, 25]
