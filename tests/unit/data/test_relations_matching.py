"""Matching relation stamps to scan stamps: one lookup for the metric and for benchmark slices."""

from __future__ import annotations

import numpy as np
import pytest

from albot1.data.model import Relations
from albot1.data.relations import STAMP_TOLERANCE_S, match_stamps, relations_in_run


def test_nearest_stamp_and_gap_in_sorted_stamps() -> None:
    idx, gap = match_stamps([0.0, 1.0, 2.0], [0.4, 0.6, 2.05, -0.01, 1.0])
    assert idx.tolist() == [0, 1, 2, 0, 1]
    np.testing.assert_allclose(gap, [0.4, 0.4, 0.05, 0.01, 0.0], atol=1e-15)


def test_unsorted_stamps_give_indices_in_the_given_order() -> None:
    stamps = [10.0, 12.0, 11.5, 13.0, 11.9]  # stamps that go back, as in the Intel log
    idx, gap = match_stamps(stamps, [11.5, 12.0, 11.9, 13.0, 10.0, 11.96])
    assert idx.tolist() == [2, 1, 4, 3, 0, 1]
    np.testing.assert_allclose(gap, [0, 0, 0, 0, 0, 0.04], atol=1e-12)


def test_equal_stamps_resolve_to_the_first_in_log_order() -> None:
    idx, _ = match_stamps([3.0, 1.0, 1.0, 2.0], [1.0])
    assert idx.tolist() == [1]


def test_the_tolerance_accepts_five_decimal_rounding_and_refuses_the_intel_neighbour_spacing() -> None:
    assert STAMP_TOLERANCE_S >= 5e-6 * 10
    assert STAMP_TOLERANCE_S < 0.509e-3 / 2  # the closest two scans of the five Freiburg logs


def test_empty_stamps_are_refused() -> None:
    with pytest.raises(ValueError, match="no timestamps"):
        match_stamps([], [1.0])


def test_a_relation_applies_when_both_ends_are_scans_of_the_run_with_rounded_stamps() -> None:
    relations = Relations(
        t1=np.array([100.00001, 101.0, 102.0, 100.0]),
        t2=np.array([101.0, 103.0, 104.0, 104.00003]),
        poses=np.arange(12, dtype=float).reshape(4, 3),
    )
    assert relations_in_run(relations, np.array([104.0, 100.0, 101.0, 102.0])).tolist() == [True, False, True, True]
    assert relations_in_run(relations, np.array([100.5])).tolist() == [False] * 4
    assert relations_in_run(relations, np.array([])).tolist() == [False] * 4


def test_a_relation_naming_a_skipped_scan_inside_the_runs_time_span_does_not_apply() -> None:
    """Every second scan of 0..9 s: (0, 1) lies inside the run's time span, but scan 1 was not seen."""
    kept = np.arange(0.0, 10.0, 2.0)
    relations = Relations(np.array([0.0, 2.0, 8.0, 3.0]), np.array([1.0, 8.0, 2.0, 4.0]), np.zeros((4, 3)))
    assert relations_in_run(relations, kept).tolist() == [False, True, True, False]


def test_the_tolerance_decides_a_near_stamp() -> None:
    relations = Relations(np.array([0.0]), np.array([1.0 + 2e-4]), np.zeros((1, 3)))
    assert relations_in_run(relations, np.array([0.0, 1.0])).tolist() == [False]
    assert relations_in_run(relations, np.array([0.0, 1.0]), tolerance_s=3e-4).tolist() == [True]
