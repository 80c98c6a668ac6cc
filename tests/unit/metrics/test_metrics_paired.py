"""The one paired comparison (albot1.metrics.paired): pooled ratio, seeded block bootstrap, verdicts, n/a."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.metrics.paired import (
    BETTER,
    MIN_PAIRS,
    NOT_APPLICABLE,
    PERFECT_REFERENCE,
    RATIO_TIE,
    SAME,
    UNBOUNDED,
    WORSE,
    bootstrap_ratio,
    compare,
    method_text,
    ratio_digits,
    strata,
    verdict,
)


def test_the_ratio_is_the_pooled_rmse_ratio_and_a_clear_difference_is_significant() -> None:
    rng = np.random.default_rng(1)
    odo = [np.abs(rng.normal(1.0, 0.1, 200)), np.abs(rng.normal(1.0, 0.1, 150))]
    worse = [(2.0 * o, o) for o in odo]
    ratio, low, high = bootstrap_ratio(worse, resamples=200)
    assert ratio == pytest.approx(2.0)
    assert low == pytest.approx(2.0) and high == pytest.approx(2.0)  # paired: every resample has ratio 2
    better = [(0.5 * o + rng.normal(0, 0.01, len(o)), o) for o in odo]
    ratio, low, high = bootstrap_ratio(better, resamples=200)
    assert high < 1.0 and low < ratio < high


def test_equal_errors_up_to_noise_are_indistinguishable_and_the_draws_are_seeded() -> None:
    rng = np.random.default_rng(2)
    odo = np.abs(rng.normal(1.0, 0.5, 300))
    method = odo[rng.permutation(300)]  # the same errors at other scans: the same RMSE, unpaired noise
    first = bootstrap_ratio([(method, odo)], resamples=300)
    assert first == bootstrap_ratio([(method, odo)], resamples=300)
    assert first[1] < 1.0 < first[2]
    assert first != bootstrap_ratio([(method, odo)], resamples=300, seed=1)  # the seed is what fixes the draws


def test_power_one_is_the_ratio_of_means() -> None:
    a, b = np.array([1.0, 2.0, 3.0, 6.0]), np.array([2.0, 2.0, 2.0, 2.0])
    assert bootstrap_ratio([(a, b)], power=1, resamples=10)[0] == pytest.approx(12.0 / 8.0)
    assert bootstrap_ratio([(a, b)], power=2, resamples=10)[0] == pytest.approx(math.sqrt(50.0 / 16.0))


def test_a_known_better_method_is_better_and_its_mirror_worse() -> None:
    b = np.linspace(1.0, 2.0, 100)
    found = compare([(0.5 * b, b)], power=1, resamples=100)
    assert (found.verdict, found.ratio, found.low, found.high) == (BETTER, 0.5, 0.5, 0.5)
    assert (found.pairs, found.groups, found.reason) == (100, 1, None)
    back = found.mirrored()
    assert (back.verdict, back.ratio, back.low, back.high) == (WORSE, 2.0, 2.0, 2.0)
    assert found.text() == "0.5 [0.5–0.5]" and found.short() == "< 0.5" and back.short() == "> 2"


def test_identical_errors_are_indistinguishable_with_ratio_exactly_one() -> None:
    errors = [np.abs(np.sin(np.arange(50.0))), np.arange(30.0)]
    found = compare([(e, e) for e in errors], resamples=100)
    assert (found.verdict, found.ratio, found.low, found.high) == (SAME, 1.0, 1.0, 1.0)
    assert (found.pairs, found.groups) == (80, 2)
    assert found.short() == "≈ 1"


def test_too_few_pairs_or_no_reference_error_is_not_applicable_with_its_reason() -> None:
    few = compare([(np.ones(MIN_PAIRS - 1), np.ones(MIN_PAIRS - 1))])
    assert few.verdict == NOT_APPLICABLE and few.reason == f"{MIN_PAIRS - 1} pairs, fewer than {MIN_PAIRS}"
    assert few.text() == f"n/a ({MIN_PAIRS - 1} pairs, fewer than {MIN_PAIRS})" and few.short() == "–"
    zero = compare([(np.ones(20), np.zeros(20))])
    assert zero.verdict == NOT_APPLICABLE and zero.reason == PERFECT_REFERENCE
    assert compare([(np.ones(20), np.full(20, 1e-9))]).reason == PERFECT_REFERENCE  # numerical noise: no ratio
    perfect = compare([(np.zeros(20), np.ones(20))], resamples=20)
    assert perfect.verdict == BETTER and perfect.short() == "< 0"  # a perfect method is better
    # B against a perfect A is what compare(B, A) says: no ratio (never "inf" printed as a number)
    back = perfect.mirrored()
    assert (back.verdict, back.reason, back.text(), back.short()) == (
        NOT_APPLICABLE,
        PERFECT_REFERENCE,
        f"n/a ({PERFECT_REFERENCE})",
        "–",
    )
    assert compare([(np.ones(20), np.zeros(20))], resamples=20).reason == back.reason
    assert compare([(np.full(20, np.nan), np.ones(20))]).reason == "a non-finite error"
    with pytest.raises(ValueError, match="differ in length"):
        compare([(np.ones(20), np.ones(21))])


def test_the_verdict_reads_the_interval_against_one() -> None:
    assert [verdict(0.5, 0.9), verdict(1.1, 1.5), verdict(0.9, 1.1), verdict(1.0, 1.0)] == [BETTER, WORSE, SAME, SAME]
    assert "paired moving-block bootstrap" in method_text() and "95%" in method_text()


def test_the_numbers_are_those_of_the_generalisation_page_before_the_move() -> None:
    """Pinned: the bootstrap of ``albot1/report/generalisation.py`` (commit e309a8d) gave exactly these floats."""
    a = np.abs(np.sin(np.arange(137.0))) + 0.1
    b = np.abs(np.cos(np.arange(137.0) * 0.7)) + 0.2
    c = np.linspace(0.1, 1.0, 61)
    assert bootstrap_ratio([(a, b), (c, c[::-1].copy())], resamples=300, seed=3) == (
        0.9105986048453787,
        0.8409428987692522,
        0.9821878188620228,
    )


def _gathered_one_index_at_a_time(
    pairs: list[tuple[np.ndarray, np.ndarray]], power: int, resamples: int, seed: int
) -> tuple[float, float]:
    """The bootstrap as first written: every resample's indices built, the errors gathered, each draw pooled alone."""
    from albot1.metrics.paired import _block_starts, _pooled, _shape

    powered = [(a**power, b**power) for a, b in pairs]
    shapes = tuple(_shape(len(a)) for a, _ in powered)
    starts = _block_starts(shapes, resamples, seed)
    num, den = np.zeros(resamples), np.zeros(resamples)
    for (a, b), (n, length, _), first in zip(powered, shapes, starts, strict=True):
        idx = (first[:, :, None] + np.arange(length)).reshape(resamples, -1)[:, :n]
        num += a[idx].sum(axis=1)
        den += b[idx].sum(axis=1)
    draws = np.array([_pooled(float(x), float(y), power) for x, y in zip(num, den, strict=True)])
    tail = (1.0 - 0.95) / 2  # as the module computes it (not exactly 0.025)
    low, high = np.quantile(draws, [tail, 1.0 - tail])
    return float(low), float(high)


@pytest.mark.parametrize("power", [1, 2])
@pytest.mark.parametrize("lengths", [(11,), (37, 5, 400), (1203,), (20, 21, 19)])
def test_the_block_copies_give_the_bits_of_the_index_by_index_gather(power: int, lengths: tuple[int, ...]) -> None:
    """The interval is bit for bit the one of gathering each resample's errors index by index (issue 24's speed-up)."""
    rng = np.random.default_rng(sum(lengths) + power)
    pairs = [(rng.gamma(2.0, 0.3, n), rng.gamma(2.0, 0.35, n)) for n in lengths]
    pairs[0][1][: len(pairs[0][1]) // 2] = 0.0  # resamples whose B error is zero: an infinite draw, as before
    _, low, high = bootstrap_ratio(pairs, power=power, resamples=700, seed=11)
    assert (low, high) == _gathered_one_index_at_a_time(pairs, power, 700, 11)


@pytest.mark.parametrize("power", [1, 2])
def test_a_nan_error_and_an_empty_group_give_the_gathers_numbers(power: int) -> None:
    """A NaN error makes NaN draws (not infinite ones) and an empty group adds nothing, as in the gather."""
    rng = np.random.default_rng(5 + power)
    a, b = rng.gamma(2.0, 0.3, 30), rng.gamma(2.0, 0.35, 30)
    b[7] = np.nan
    pairs = [(a, b), (np.array([]), np.array([])), (rng.gamma(2.0, 0.3, 12), rng.gamma(2.0, 0.3, 12))]
    _, low, high = bootstrap_ratio(pairs, power=power, resamples=300, seed=2)
    expected = _gathered_one_index_at_a_time(pairs, power, 300, 2)
    assert np.array_equal([low, high], expected, equal_nan=True), ((low, high), expected)


def test_a_reference_zero_on_nearly_every_pair_has_no_interval_and_says_why() -> None:
    """Many resamples draw only zeros of B: the upper end is inf or NaN, never a bound (old: "3.47 [2.12–n/a]")."""
    a = np.random.default_rng(3).uniform(0.1, 1.0, 50)
    b = a.copy()
    b[:45] = 0.0
    _, low, high = bootstrap_ratio([(a, b)], resamples=2000)
    assert math.isfinite(low) and not math.isfinite(high)  # what compare must not pass on as an interval
    found = compare([(a, b)])
    assert (found.verdict, found.reason, found.text()) == (NOT_APPLICABLE, UNBOUNDED, f"n/a ({UNBOUNDED})")
    assert (found.pairs, found.groups) == (50, 1)
    # the same errors the other way round: A's resampled error is zero in over 2.5 % of the draws, so the
    # interval's lower end is 0 and its mirror would reach inf; mirrored says what compare(B, A) says
    forward = compare([(b, a)])
    assert forward.verdict == BETTER and forward.low == 0.0
    assert (forward.mirrored().verdict, forward.mirrored().reason) == (NOT_APPLICABLE, UNBOUNDED)


def test_a_mirror_swaps_the_pooled_errors_and_keeps_the_evidence() -> None:
    rng = np.random.default_rng(9)
    a, b = rng.uniform(0.1, 0.5, 40), rng.uniform(0.6, 1.0, 40)
    found = compare([(a, b)], resamples=200)
    back = found.mirrored()
    assert (found.error_a, found.error_b) == (math.sqrt(np.mean(a * a)), math.sqrt(np.mean(b * b)))
    assert (back.error_a, back.error_b) == (found.error_b, found.error_a)
    assert (back.ratio, back.low, back.high, back.verdict) == (1 / found.ratio, 1 / found.high, 1 / found.low, WORSE)


def test_runs_of_one_pair_each_are_resampled_together_not_given_an_interval_of_zero_width() -> None:
    """A dozen seeds of one relation each (a short slice): each run resampled within itself drew its one pair in
    every resample, so the interval had zero width and noise was called a difference (``worse 1.17 [1.17–1.17]``).
    The runs are independent: their pairs are one stratum, and the interval is that of the twelve pairs pooled."""
    rng = np.random.default_rng(0)
    a, b = rng.uniform(0.0, 1.0, 12), rng.uniform(0.0, 1.0, 12)
    runs = compare([(a[k : k + 1], b[k : k + 1]) for k in range(12)], power=1)
    pooled = compare([(a, b)], power=1)
    assert runs.low < runs.ratio < runs.high and runs.verdict == SAME
    assert (runs.ratio, runs.low, runs.high, runs.verdict) == (pooled.ratio, pooled.low, pooled.high, SAME)
    assert (runs.pairs, runs.groups) == (12, 12)  # the page still counts the runs the pairs come from
    # runs of several pairs keep their strata: with one run of one pair beside them, the same numbers as before
    long = [(rng.gamma(2.0, 0.3, 40), rng.gamma(2.0, 0.3, 40)) for _ in range(2)]
    one = (np.array([0.3]), np.array([0.4]))
    assert strata([*long, one]) == [*long, one]
    merged = strata([long[0], one, long[1], one])
    assert len(merged) == 3 and merged[0] is long[0] and merged[2] is long[1]
    assert merged[1][0].tolist() == [0.3, 0.3] and merged[1][1].tolist() == [0.4, 0.4]


def test_a_ratio_within_rounding_of_one_is_a_tie_and_a_verdict_prints_the_side_of_one_it_is_on() -> None:
    """``worse 1 [1–1]``: a 0.04 % difference printed at 3 digits read as a tie called worse, and errors equal
    but for float rounding (1e-12 apart) were called worse: a verdict from the last bit."""
    b = np.random.default_rng(0).uniform(0.1, 1.0, 200)
    noise = compare([(b + 1e-12, b)])
    assert noise.verdict == SAME and noise.text() == "1 [1–1]"
    assert verdict(1.0 + RATIO_TIE / 2, 1.0 + RATIO_TIE) == SAME
    assert verdict(1.0 - 2 * RATIO_TIE, 1.0 - 1.5 * RATIO_TIE) == BETTER
    slightly = compare([(b * 1.0004, b)])
    assert slightly.verdict == WORSE
    assert slightly.text() == "1.0004 [1.0004–1.0004]" and slightly.short() == "> 1.0004"
    back = slightly.mirrored()
    assert back.verdict == BETTER and back.text() == "0.9996 [0.9996–0.9996]"
    close = compare([(b * (1 - 3e-6), b)])
    assert close.verdict == BETTER and close.text().startswith("0.999997 [")
    assert ratio_digits(0.8, 1.2) == 3 and ratio_digits(1.2, 1.5) == 3  # an interval that reads well stays at 3
    assert ratio_digits(0.9, 0.99999) == 5  # 0.99999 at 3 digits rounds up to 1
