"""RPE per travelled distance (``drift``) and ATE over windows (``ate_windows``) on exact geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.metrics.ate import ate, windowed_ate
from albot1.metrics.drift import drift, segment_pairs
from albot1.metrics.errors import MetricsError


def straight(n_steps: int, step_m: float) -> np.ndarray:
    return se2.integrate_steps([0.0, 0.0, 0.0], np.tile([[step_m, 0.0, 0.0]], (n_steps, 1)))


def test_segments_start_every_metre_and_end_at_the_length() -> None:
    ref = straight(300, 0.1)  # 30 m in 0.1 m steps
    pairs = segment_pairs(ref, 10.0)
    # Starts at 0, 1, ..., 20 m (a 10 m segment must fit): 21 pairs, each exactly 100 scans long.
    assert len(pairs) == 21
    np.testing.assert_array_equal(pairs[:, 0], np.arange(0, 201, 10))
    np.testing.assert_array_equal(pairs[:, 1] - pairs[:, 0], 100)


def test_standing_still_adds_no_segment() -> None:
    ref = straight(300, 0.1)
    paused = np.vstack([ref[:50], np.repeat(ref[50:51], 40, axis=0), ref[51:]])  # 40 scans parked at 5 m
    assert len(segment_pairs(paused, 10.0)) == len(segment_pairs(ref, 10.0))


def test_scale_error_gives_one_percent_of_the_length() -> None:
    ref = straight(300, 0.1)
    est = straight(300, 0.101)  # odometry over-reporting distance by 1 %
    block = drift(est, ref)
    assert block["at_10m"]["translation_m"] == pytest.approx(0.1, abs=1e-9)
    assert block["at_10m"]["rotation_deg"] == pytest.approx(0.0, abs=1e-12)
    assert block["at_10m"]["pairs"] == 21
    sweep = {entry["length_m"]: entry for entry in block["sweep"]}
    for length in (1.0, 2.0, 5.0, 10.0, 20.0):
        assert sweep[length]["translation_m"]["max"] == pytest.approx(0.01 * length, abs=1e-9)
    assert block["lengths_beyond_route_m"] == [50.0, 100.0]


def test_heading_drift_per_segment() -> None:
    ref = straight(300, 0.1)
    est = se2.integrate_steps([0.0, 0.0, 0.0], np.tile([[0.1, 0.0, 0.001]], (300, 1)))  # 0.001 rad per step
    block = drift(est, ref)
    # 100 steps per 10 m segment: 0.1 rad of heading error on every one of them.
    assert block["at_10m"]["rotation_deg"] == pytest.approx(math.degrees(0.1), abs=1e-9)
    sweep = {entry["length_m"]: entry for entry in block["sweep"]}
    assert sweep[1.0]["rotation_deg"]["mean"] == pytest.approx(math.degrees(0.01), abs=1e-9)


def test_drift_ignores_a_rigid_motion_of_the_estimate() -> None:
    ref = straight(300, 0.1)
    est = se2.integrate_steps([0.0, 0.0, 0.0], np.tile([[0.1, 0.002, 0.001]], (300, 1)))
    moved = se2.compose(np.array([3.0, -2.0, 1.1]), est)
    a, b = drift(est, ref), drift(moved, ref)
    assert a["at_10m"]["translation_m"] == pytest.approx(b["at_10m"]["translation_m"], abs=1e-9)


def test_a_short_route_has_no_10m_headline() -> None:
    ref = straight(50, 0.1)
    block = drift(ref, ref)
    assert block["at_10m"] is None and "5.0 m of reference travel" in block["at_10m_reason"]
    assert [e["length_m"] for e in block["sweep"]] == [1.0, 2.0, 5.0]


def test_windows_align_each_window_alone() -> None:
    """A route bent at each window boundary: every window is a rigid copy (zero), the whole-log ATE is not."""
    ref = straight(200, 1.0)  # 200 m, four 50 m windows
    steps = np.tile([[1.0, 0.0, 0.0]], (200, 1))
    steps[[49, 99, 149], 2] = [0.1, -0.2, 0.3]  # a heading error arriving exactly at scans 50, 100 and 150
    est = se2.integrate_steps([0.0, 0.0, 0.0], steps)
    block = windowed_ate(est, ref)
    assert block["windows"] == 4 and block["uncovered_m"] == pytest.approx(0.0)
    assert [(w["first_scan"], w["last_scan"]) for w in block["per_window"]] == [
        (0, 50),
        (50, 100),
        (100, 150),
        (150, 200),
    ]
    assert block["mean_rmse_m"] == pytest.approx(0.0, abs=1e-9)
    assert ate(est, ref)["rmse_m"] > 1.0


def test_windows_of_an_exact_copy_score_zero_and_the_tail_is_reported() -> None:
    ref = straight(230, 1.0)
    block = windowed_ate(ref, ref)
    assert block["windows"] == 4 and block["uncovered_m"] == pytest.approx(30.0)
    assert block["mean_rmse_m"] == pytest.approx(0.0, abs=1e-12)
    assert block["window_rmse"]["n"] == 4


def test_an_offset_in_one_window_shows_in_that_window_only() -> None:
    ref = straight(200, 1.0)
    est = ref.copy()
    est[120:130, 1] += 1.0  # a 10-scan excursion inside the third window
    per = [w["rmse_m"] for w in windowed_ate(est, ref)["per_window"]]
    assert per[0] == per[1] == per[3] == pytest.approx(0.0, abs=1e-12)
    assert per[2] > 0.3


def test_fewer_than_two_windows_is_an_error() -> None:
    ref = straight(79, 1.0)
    with pytest.raises(MetricsError, match=r"route \(79.0 m of reference travel\) is shorter than two 50 m windows"):
        windowed_ate(ref, ref)


def test_a_window_no_scan_falls_in_is_left_out_not_scored_zero() -> None:
    """A reference with a 100 m gap (a sparse reference file): the two windows inside the gap held one scan each,
    which its own alignment put on the reference exactly, an RMSE of 0 by construction: the mean fell from 0.70 m
    (the one window that holds scans) to 0.23 m."""
    travel = np.r_[np.arange(50.0), 149.0 + np.arange(1.0, 40.0)]  # 0..49 m, then a jump to 150 m, on to 188 m
    ref = np.column_stack([travel, np.zeros(len(travel)), np.zeros(len(travel))])
    est = ref + np.column_stack([np.zeros(len(travel)), np.sin(np.arange(len(travel))), np.zeros(len(travel))])
    with pytest.raises(MetricsError, match=r"1 of the route's 3 50 m windows hold a scan .*; expected at least two"):
        windowed_ate(est, ref)
    longer = np.r_[travel, 188.0 + np.arange(1.0, 60.0)]  # on to 247 m: windows 0-50 and 150-200 hold scans
    ref = np.column_stack([longer, np.zeros(len(longer)), np.zeros(len(longer))])
    est = ref + np.column_stack([np.zeros(len(longer)), np.sin(np.arange(len(longer))), np.zeros(len(longer))])
    block = windowed_ate(est, ref)
    assert (block["windows"], block["windows_without_scan"]) == (2, 2)
    assert [(w["first_scan"], w["last_scan"]) for w in block["per_window"]] == [(0, 50), (50, 100)]
    assert all(w["rmse_m"] > 0.5 for w in block["per_window"]) and block["window_rmse"]["min_m"] > 0.5
