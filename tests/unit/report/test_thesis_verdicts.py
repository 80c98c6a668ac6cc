"""Verdict functions: the right word on either side of each claim's threshold, and never a number made up."""

from __future__ import annotations

import math

import pytest

from albot1.report.thesis.claims import READINGS, TABLE_3_1, THESIS
from albot1.report.thesis.verdicts import (
    FAILS,
    HOLDS,
    NOT_COMPARABLE,
    Number,
    Verdict,
    all_of,
    at_least,
    at_most,
    close_to,
    equals,
    lower_than,
    quantity,
    ratio_at_least,
)


def m(label: str, value: float | None, unit: str = "m", missing: str | None = None) -> Number:
    return Number(label, value, unit, missing)


def test_loop_gap_ratio_either_side_of_the_reading() -> None:
    ratio = READINGS["gap_ratio"].value
    odometry = m("odometry", 5.1)
    holds = ratio_at_least(m("albot1 loop gap", 0.6), odometry, ratio, thesis="0.4 m vs 4.6 m, 11.5x")
    assert holds.word == HOLDS
    assert (
        holds.reason == "albot1 loop gap 0.600 m vs odometry 5.10 m (8.50x, at least 2x; thesis 0.4 m vs 4.6 m, 11.5x)"
    )
    assert ratio_at_least(m("albot1", 5.1 / ratio), odometry, ratio).word == HOLDS  # exactly at the threshold
    fails = ratio_at_least(m("albot1", 5.1 / ratio + 0.01), odometry, ratio)
    assert fails.word == FAILS
    assert "below 2x" in fails.reason
    assert ratio_at_least(m("albot1", 0.0), odometry, ratio).word == HOLDS  # a perfect loop: infinitely better


def test_a_missing_number_is_not_comparable_with_its_own_reason() -> None:
    missing = m("albot1:plus loop gap", None, missing="failed in results/thesis (timeout: over 600 s)")
    verdict = ratio_at_least(missing, m("odometry", 4.6), 2.0)
    assert verdict.word == NOT_COMPARABLE
    assert verdict.reason == "albot1:plus loop gap: failed in results/thesis (timeout: over 600 s)"
    nan = ratio_at_least(m("albot1", math.nan, missing="no value"), m("odometry", 4.6), 2.0)
    assert nan.word == NOT_COMPARABLE
    for verdict in (
        at_most(missing, 1.0),
        at_least(missing, 1.0),
        equals(missing, 6.0),
        close_to(missing, 4.6, 0.25),
        lower_than(missing, m("odometry", 1.0)),
        lower_than(m("a", 1.0), missing),
    ):
        assert verdict.word == NOT_COMPARABLE
        assert "failed in results/thesis" in verdict.reason


@pytest.mark.parametrize(
    ("value", "strict", "word"),
    [(0.35, False, HOLDS), (0.5, False, HOLDS), (0.51, False, FAILS), (0.99, True, HOLDS), (1.0, True, FAILS)],
)
def test_at_most(value: float, strict: bool, word: str) -> None:
    bound = 1.0 if strict else READINGS["dense_updates_per_view"].value
    assert at_most(Number("updates/view", value), bound, strict=strict).word == word


@pytest.mark.parametrize(("median_m", "word"), [(0.4, HOLDS), (1.0, HOLDS), (1.01, FAILS)])
def test_shape_kept_reading(median_m: float, word: str) -> None:
    verdict = at_most(m("albot1 median map-to-wall", median_m), READINGS["shape_median_m"].value)
    assert verdict.word == word
    assert verdict.reason.startswith(f"albot1 median map-to-wall {median_m:.3g}")


@pytest.mark.parametrize(
    ("value", "strict", "word"), [(0.49, False, FAILS), (0.5, False, HOLDS), (0.0, True, FAILS), (0.1, True, HOLDS)]
)
def test_at_least(value: float, strict: bool, word: str) -> None:
    bound = 0.0 if strict else 0.5
    verdict = at_least(Number("map precision", value), bound, strict=strict)
    assert verdict.word == word


def test_orientation_claim_needs_both_bounds() -> None:
    angle, distance = THESIS["orientation_max_angle_deg"].value, THESIS["orientation_max_distance_m"].value

    def claim(bearing: float, dist: float) -> Verdict:
        return all_of([at_most(m("bearing", bearing, "deg"), angle), at_most(m("distance", dist), distance)])

    assert claim(6.9, 2.9).word == HOLDS
    assert claim(7.1, 2.9).word == FAILS
    assert claim(6.9, 3.1).word == FAILS
    assert claim(7.1, 3.1).reason == "bearing 7.10 deg > 7 deg; distance 3.10 m > 3 m"


def test_all_of_a_failing_part_decides_even_when_another_is_unknown() -> None:
    fails = Verdict(FAILS, "places 5 != 6")
    unknown = Verdict(NOT_COMPARABLE, "recall: no counter")
    good = Verdict(HOLDS, "precision 1 = 1")
    assert all_of([good, unknown]).word == NOT_COMPARABLE
    assert all_of([good, unknown]).reason == "recall: no counter"
    assert all_of([unknown, fails, good]) == Verdict(FAILS, "places 5 != 6")
    assert all_of([good, good]).word == HOLDS
    assert all_of([]).word == NOT_COMPARABLE


def test_setup_reproduction_within_the_tolerance() -> None:
    tolerance = READINGS["setup_tolerance"].value
    target = THESIS["exp3_odometry_gap_m"].value
    verdict = close_to(m("odometry loop gap", 4.61), target, tolerance)
    assert verdict.word == HOLDS
    assert verdict.reason.startswith("odometry loop gap 4.61 m is 0.217 % from 4.60 m (within 25 %")
    assert close_to(m("odometry loop gap", 1.70), target, tolerance).word == FAILS  # the office loop's gap
    assert close_to(m("odometry loop gap", target * 1.249), target, tolerance).word == HOLDS
    assert close_to(m("odometry loop gap", target * 1.251), target, tolerance).word == FAILS


def test_comparisons_and_counts() -> None:
    assert lower_than(m("albot1 relation error", 0.3), m("odometry", 0.55)).word == HOLDS
    assert lower_than(m("albot1 relation error", 0.55), m("odometry", 0.55)).word == FAILS
    assert lower_than(m("albot1 median map-to-wall", 0.3), m("mrpt-rbpf", 1.4)).word == HOLDS
    places = THESIS["places_single_loop"].value
    assert equals(Number("places", 6.0, "places"), places).word == HOLDS
    assert equals(Number("places", 7.0, "places"), places).reason == "places 7 places != 6 places"


def test_thesis_numbers_carry_their_source_and_table_3_1_is_as_printed() -> None:
    for key, number in THESIS.items():
        assert number.source and number.what, key
    assert THESIS["exp3_odometry_gap_m"].text() == "4.6 m"
    assert [round(s.angle_difference_deg, 2) for s in TABLE_3_1] == [5.4, 6.0, 3.5, 6.5]
    assert [round(s.distance_difference_m, 2) for s in TABLE_3_1] == [1.5, 2.65, 3.2, 1.4]


def test_quantity_has_three_significant_digits() -> None:
    assert quantity(4.6065, "m") == "4.61 m"
    assert quantity(0.35338) == "0.353"
    assert quantity(123.4, "deg") == "123 deg"
    assert quantity(106.0, "views") == "106 views"
    assert quantity(1.0) == "1"


def test_a_lower_mean_holds_only_when_the_paired_test_says_better() -> None:
    import numpy as np

    from albot1.metrics.paired import compare, not_applicable
    from albot1.report.thesis.verdicts import with_paired_test

    point = lower_than(Number("albot1", 0.4, "m"), Number("odometry", 0.5, "m"))
    assert point.word == HOLDS
    base = np.linspace(1.0, 2.0, 60)
    better = with_paired_test(point, compare([(0.8 * base, base)], power=1, resamples=50))
    assert better.word == HOLDS and better.reason.endswith("over 60 pairs: better at 95%")
    noise = np.where(np.arange(60) % 2 == 0, 1.6, 0.4) * base  # lower on average, but not on every stretch
    tied = with_paired_test(point, compare([(noise, base)], power=1, resamples=50))
    assert tied.word == FAILS and "indistinguishable at 95%" in tied.reason
    untested = with_paired_test(point, not_applicable("4 pairs, fewer than 10"))
    assert untested.word == HOLDS and untested.reason.endswith("; no paired test (4 pairs, fewer than 10)")
    missing = lower_than(Number("albot1", None, "m", "failed"), Number("odometry", 0.5, "m"))
    assert with_paired_test(missing, compare([(0.8 * base, base)], power=1, resamples=50)) == missing


def test_two_zero_loop_gaps_make_no_ratio() -> None:
    verdict = ratio_at_least(m("albot1 loop gap", 0.0), m("odometry", 0.0), 2.0, thesis="0.4 m vs 4.6 m, 11.5x")
    assert verdict == Verdict(
        NOT_COMPARABLE,
        "albot1 loop gap 0 m vs odometry 0 m: no ratio of two zeros, nothing to improve on; thesis 0.4 m vs 4.6 m, "
        "11.5x",
    )
