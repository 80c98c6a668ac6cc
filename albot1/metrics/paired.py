"""Paired comparison of two methods' errors: a ratio, its bootstrap interval and a verdict.

Why one implementation: a page that says "A beats B" must carry the evidence,
and every page (the generalisation page, the standard benchmark, the metrics
tables, the thesis page) must mean the same thing by it. The errors of A and
B are *paired*: the same scans or the same ground-truth relations of the
same runs (same dataset, degradation and seed), so the noise the two share
cancels and only their difference is tested.

The statistic is the ratio of A's pooled error to B's,
``(sum a^p / sum b^p) ** (1/p)`` over every pair of every group: ``p = 2``
is the ratio of two RMSEs (ATE), ``p = 1`` the ratio of two means (the
relation metric). Below 1, A's error is the smaller.

Its interval is a paired **moving-block bootstrap**: errors along a route are
correlated (one bad stretch spoils many consecutive scans or relations), so
each group (a run: one seed) is resampled as blocks of ``1/BLOCKS`` of its
length, with the same indices for A and B, within the group (the groups are
strata; their number is kept), except that runs of a single pair are
resampled together as one stratum (a run of one pair resampled within itself
draws that pair every time, so runs of one pair each would give an interval
of zero width: a certainty the data do not hold). :data:`RESAMPLES`
resamples from a fixed seed make the interval reproducible: the same errors
give the same page. A is **better** when the whole ``CONFIDENCE`` interval is
below 1, **worse** when it is above 1, else **indistinguishable**; an
interval within :data:`RATIO_TIE` of 1 is a tie (rounding, not a difference),
and a ratio is printed with the digits that show which side of 1 its
interval lies on (``1.0004 [1.0003–1.0005]``, never ``worse 1 [1–1]``). A comparison with fewer than
:data:`MIN_PAIRS` pairs, or where B's error is zero, does not apply and says
why (a bootstrap over a handful of values claims more than it knows). Nor
does one whose interval is unbounded: when B's errors are zero on nearly
every pair, more than ``(1 - CONFIDENCE) / 2`` of the resamples draw only
zeros of B, their ratio has no value, and an interval end of "inf" (or NaN,
where numpy's quantile interpolates between two of them) would be printed
as if it were a number.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Final

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import ArrayLike, NDArray

CONFIDENCE: Final = 0.95
RESAMPLES: Final = 2000
#: blocks per group of the moving-block bootstrap (errors are correlated along the route)
BLOCKS: Final = 20
#: fewest pairs (over all groups) a comparison is made on
MIN_PAIRS: Final = 10
#: a pooled error below this (m or deg) is zero: a perfect reference (e.g. the reference poses given as odometry),
#: to which a ratio is numerical noise
ZERO_ERROR: Final = 1e-6
#: an interval within this relative distance of 1 is a tie (indistinguishable): the float rounding of the errors
#: (a 1 mm error computed from poses 1e6 m from the origin is rounded by ~1e-7 of itself) moves a ratio of two
#: methods with the same poses this far; the report's check that errors reproduce uses the same 1e-6
RATIO_TIE: Final = 1e-6
#: significant digits of a ratio on the pages (more where they are needed to show the interval's side of 1)
DIGITS: Final = 3
#: resamples whose indices are built at once (memory: CHUNK x the longest group's length)
CHUNK: Final = 250

BETTER: Final = "better"
WORSE: Final = "worse"
SAME: Final = "indistinguishable"
NOT_APPLICABLE: Final = "n/a"
PERFECT_REFERENCE: Final = f"the reference error is below {ZERO_ERROR:g} (perfect): no ratio"
NEGATIVE_ERROR: Final = "a negative error (expected magnitudes >= 0: a distance or an absolute angle)"
UNBOUNDED: Final = (
    "the reference error is zero in too many resamples (zero on nearly every pair): the interval is unbounded"
)
#: the verdict read from the other side (B against A)
MIRROR: Final = {BETTER: WORSE, WORSE: BETTER, SAME: SAME, NOT_APPLICABLE: NOT_APPLICABLE}
#: one character per verdict, for compact matrices: A's error is smaller / larger / not told apart
SYMBOL: Final = {BETTER: "<", WORSE: ">", SAME: "≈", NOT_APPLICABLE: "–"}

Pair = tuple[NDArray[np.float64], NDArray[np.float64]]


@dataclass(frozen=True)
class Comparison:
    """A against B: the pooled error ratio, its bootstrap interval and the verdict (or why there is none)."""

    ratio: float
    low: float
    high: float
    verdict: str  # better | worse | indistinguishable | n/a
    pairs: int
    groups: int
    reason: str | None = None
    #: A's and B's pooled errors (``(mean e^p) ** (1/p)``): the mirror needs A's to know whether A is perfect
    error_a: float = math.nan
    error_b: float = math.nan

    @property
    def applies(self) -> bool:
        return self.verdict != NOT_APPLICABLE

    def mirrored(self) -> Comparison:
        """B against A: the reciprocal ratio and interval, the opposite verdict (the same evidence).

        When A is the perfect one (its pooled error below :data:`ZERO_ERROR`), or a resample quantile of A's
        error is zero (the reciprocal interval unbounded), B against A does not apply, with the reason
        :func:`compare` gives for those errors in that order: never a ratio of ``inf``. An n/a about B's
        errors (:data:`PERFECT_REFERENCE`, :data:`UNBOUNDED`) stays that n/a here, though it says nothing of
        B against A: compare that direction itself (``albot1.report.comparisons.all_pairs`` does).
        """
        if self.applies and self.error_a < ZERO_ERROR:
            reason: str | None = PERFECT_REFERENCE
        elif self.applies and self.low == 0.0:
            reason = UNBOUNDED
        else:
            reason = None
        if reason is not None:
            return replace(not_applicable(reason, self.pairs, self.groups), error_a=self.error_b, error_b=self.error_a)
        return Comparison(
            _reciprocal(self.ratio),
            _reciprocal(self.high),
            _reciprocal(self.low),
            MIRROR[self.verdict],
            self.pairs,
            self.groups,
            self.reason,
            self.error_b,
            self.error_a,
        )

    def text(self) -> str:
        """``0.42 [0.38–0.47]`` (3 significant digits, more where :func:`ratio_digits` needs them), or ``n/a``."""
        if not self.applies:
            return f"n/a ({self.reason})"
        digits = ratio_digits(self.low, self.high)
        return f"{ratio_text(self.ratio, digits)} [{ratio_text(self.low, digits)}–{ratio_text(self.high, digits)}]"

    def short(self) -> str:
        """``< 0.42``: the verdict's symbol and the ratio (a matrix cell); ``–`` when it does not apply."""
        if not self.applies:
            return SYMBOL[NOT_APPLICABLE]
        return f"{SYMBOL[self.verdict]} {ratio_text(self.ratio, ratio_digits(self.low, self.high))}"


def _reciprocal(value: float) -> float:
    """``1 / value`` of a ratio that is finite and positive (:meth:`Comparison.mirrored` leaves out the rest)."""
    return value if math.isnan(value) else 1.0 / value


def ratio_text(value: float, digits: int = DIGITS) -> str:
    """``digits`` significant digits; ``n/a`` for a value that is not a number (never printed as ``nan`` or ``inf``)."""
    return f"{value:.{digits}g}" if math.isfinite(value) else "n/a"


def ratio_digits(low: float, high: float) -> int:
    """The significant digits (:data:`DIGITS` or more) with which an interval's printed ends keep its side of 1.

    Why: at 3 digits an interval of 1.0003 to 1.0005 prints as ``1 [1–1]`` beside the verdict "worse", which
    reads as a contradiction (or as a tie called a difference). An interval that is entirely above or below 1
    (beyond :data:`RATIO_TIE`, as :func:`verdict` reads it) gets the digits that print its nearer end on its
    side of 1; any other keeps :data:`DIGITS`.
    """
    if not (math.isfinite(low) and math.isfinite(high)):
        return DIGITS
    if low > 1.0 + RATIO_TIE:
        end, side = low, 1.0
    elif high < 1.0 - RATIO_TIE:
        end, side = high, -1.0
    else:
        return DIGITS
    digits = DIGITS
    while digits < 17 and (float(f"{end:.{digits}g}") - 1.0) * side <= 0:
        digits += 1
    return digits


def method_text(resamples: int = RESAMPLES) -> str:
    """One sentence a page states beside its paired comparisons: which test, which confidence."""
    return (
        f"paired moving-block bootstrap ({resamples} resamples from a fixed seed, blocks of 1/{BLOCKS} of a "
        f"run resampled within each run, the same indices for both methods), {CONFIDENCE:.0%} interval of the "
        "error ratio; better / worse when the whole interval is below / above 1, else indistinguishable; "
        f"n/a (with the reason) under {MIN_PAIRS} pairs"
    )


def _pooled(num: float, den: float, power: int) -> float:
    if den <= 0:
        return math.inf
    return math.sqrt(num / den) if power == 2 else (num / den) ** (1.0 / power)


def _pooled_all(num: NDArray[np.float64], den: NDArray[np.float64], power: int) -> NDArray[np.float64]:
    """:func:`_pooled` of every resample at once (IEEE division, square root and power: the same numbers)."""
    positive = ~(den <= 0)  # as _pooled's test: a NaN sum is divided (NaN), not taken for zero (inf)
    ratio = np.divide(num, den, out=np.full(len(num), np.inf), where=positive)
    pooled = np.sqrt(ratio) if power == 2 else np.power(ratio, 1.0 / power)
    return np.where(positive, pooled, np.inf)


def _shape(n: int) -> tuple[int, int, int]:
    """``(n, block length, blocks)`` of a group of ``n`` errors."""
    length = max(1, math.ceil(n / BLOCKS))
    return n, length, math.ceil(n / length)


@lru_cache(maxsize=16)  # ~0.3 MB per group of a shape
def _block_starts(shapes: tuple[tuple[int, int, int], ...], resamples: int, seed: int) -> list[NDArray[np.int64]]:
    """Per group, the block starts of every resample (read-only: shared by every comparison of the same shapes).

    They depend on the groups' lengths and the seed only, not on the errors, so the comparisons of one table
    (the same runs' scans or relations) draw them once. Drawn resample by resample and group by group: that
    order fixes the page's numbers.
    """
    rng = np.random.default_rng(seed)
    starts = [np.empty((resamples, count), dtype=np.int64) for _, _, count in shapes]
    for k in range(resamples):
        for g, (n, length, count) in enumerate(shapes):
            starts[g][k] = rng.integers(0, n - length + 1, size=count)
    for first in starts:
        first.setflags(write=False)
    return starts


def bootstrap_ratio(
    pairs: Sequence[Pair],
    *,
    power: int = 2,
    resamples: int = RESAMPLES,
    seed: int = 0,
    confidence: float = CONFIDENCE,
) -> tuple[float, float, float]:
    """``(ratio, low, high)``: the pooled error ratio of A to B and its paired moving-block bootstrap interval.

    ``pairs``: per group (a run), A's and B's errors at the same scans or relations, in route order. The
    groups are resampled as :func:`strata` makes them.
    """
    powered = [(np.asarray(a, dtype=float) ** power, np.asarray(b, dtype=float) ** power) for a, b in strata(pairs)]
    ratio = _pooled(sum(float(np.sum(a)) for a, _ in powered), sum(float(np.sum(b)) for _, b in powered), power)
    shapes = tuple(_shape(len(a)) for a, _ in powered)
    starts = _block_starts(shapes, resamples, seed)
    num = np.zeros(resamples)
    den = np.zeros(resamples)
    for (a, b), (n, length, _), first in zip(powered, shapes, starts, strict=True):
        if n == 0:  # an empty group adds nothing to any resample (and has no window to copy)
            continue
        # a resample's blocks are copied whole from the windows of ``length`` errors, then summed as one
        # contiguous row: the same values in the same order as gathering them one index at a time (so the
        # same pairwise sums, bit for bit), at about half the cost
        windows_a, windows_b = sliding_window_view(a, length), sliding_window_view(b, length)
        for lo in range(0, resamples, CHUNK):
            chunk = first[lo : lo + CHUNK]
            num[lo : lo + CHUNK] += np.ascontiguousarray(windows_a[chunk].reshape(len(chunk), -1)[:, :n]).sum(axis=1)
            den[lo : lo + CHUNK] += np.ascontiguousarray(windows_b[chunk].reshape(len(chunk), -1)[:, :n]).sum(axis=1)
    draws = _pooled_all(num, den, power)
    tail = (1.0 - confidence) / 2
    with np.errstate(invalid="ignore"):  # inf - inf between two infinite draws: NaN, which compare() refuses
        low, high = np.quantile(draws, [tail, 1.0 - tail])
    return ratio, float(low), float(high)


def strata(pairs: Sequence[Pair]) -> list[Pair]:
    """The groups the bootstrap resamples within: each run on its own, the runs of a single pair pooled into one.

    A run of one pair resampled within itself draws that pair in every resample, so runs of one pair each
    (a short slice covering one relation per seed) would leave every resample the same and the interval of
    zero width: ``worse 1.17 [1.17–1.17]`` from a dozen noisy pairs. The runs are independent of each other,
    so their single pairs are one stratum, resampled together, in the place of the first of them. With fewer
    than two such runs nothing changes: the same strata, the same draws, the same numbers.
    """
    single = [k for k, (a, _) in enumerate(pairs) if np.asarray(a).size == 1]
    if len(single) < 2:
        return list(pairs)
    pooled: Pair = (
        np.concatenate([np.asarray(pairs[k][0], dtype=float).ravel() for k in single]),
        np.concatenate([np.asarray(pairs[k][1], dtype=float).ravel() for k in single]),
    )
    others = set(single[1:])
    return [pooled if k == single[0] else pair for k, pair in enumerate(pairs) if k not in others]


def verdict(low: float, high: float) -> str:
    """better / worse / indistinguishable from the interval of A's error ratio to B's (within :data:`RATIO_TIE`
    of 1 on either side: a tie, since rounding alone moves the ratio of two equal methods that far)."""
    if low > 1.0 + RATIO_TIE:
        return WORSE
    if high < 1.0 - RATIO_TIE:
        return BETTER
    return SAME


def not_applicable(reason: str, pairs: int = 0, groups: int = 0) -> Comparison:
    """A comparison that cannot be made, with the reason the page shows."""
    nan = math.nan
    return Comparison(nan, nan, nan, NOT_APPLICABLE, pairs, groups, reason)


def compare(
    pairs: Sequence[tuple[ArrayLike, ArrayLike]],
    *,
    power: int = 2,
    resamples: int = RESAMPLES,
    seed: int = 0,
) -> Comparison:
    """A's errors against B's (per group, the same scans or relations): ratio, interval and verdict.

    Not applicable (with the reason) when the groups hold fewer than
    :data:`MIN_PAIRS` pairs, when a group's arrays hold a non-finite or a
    negative error (:data:`NEGATIVE_ERROR`), or when B's pooled error is below
    :data:`ZERO_ERROR` (a perfect reference: no ratio). Arrays of a group
    that differ in length are a ValueError (the caller paired them wrongly).
    """
    arrays: list[Pair] = []
    for a, b in pairs:
        x, y = np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel()
        if len(x) != len(y):
            raise ValueError(f"paired errors differ in length ({len(x)} vs {len(y)})")
        if len(x):
            arrays.append((x, y))
    count = sum(len(x) for x, _ in arrays)
    if count < MIN_PAIRS:
        return not_applicable(f"{count} pairs, fewer than {MIN_PAIRS}", count, len(arrays))
    if not all(np.isfinite(x).all() and np.isfinite(y).all() for x, y in arrays):
        return not_applicable("a non-finite error", count, len(arrays))
    if any((x < 0).any() or (y < 0).any() for x, y in arrays):
        # errors are magnitudes: signed ones (a distance error, a bearing error) summed at power 1 gave a negative
        # "ratio" called better (-1 [-1–-1]) while the pooled errors beside it took their absolute values
        return not_applicable(NEGATIVE_ERROR, count, len(arrays))
    error_a = _pooled(sum(float(np.sum(np.abs(x) ** power)) for x, _ in arrays), float(count), power)
    reference = _pooled(sum(float(np.sum(np.abs(y) ** power)) for _, y in arrays), float(count), power)
    if reference < ZERO_ERROR:
        return replace(not_applicable(PERFECT_REFERENCE, count, len(arrays)), error_a=error_a, error_b=reference)
    ratio, low, high = bootstrap_ratio(arrays, power=power, resamples=resamples, seed=seed)
    if not math.isfinite(high):
        return replace(not_applicable(UNBOUNDED, count, len(arrays)), error_a=error_a, error_b=reference)
    return Comparison(ratio, low, high, verdict(low, high), count, len(arrays), None, error_a, reference)
