"""Verdicts: pure functions from a claim's test and our stored numbers to a word and a one-line reason.

Why pure functions: a verdict on the page must be computed, never typed, and
a reader must be able to check how. Each function here takes
:class:`Number` values (a measured number, or the reason there is none) and
the claim's threshold, and returns a :class:`Verdict` whose word is one of
:data:`HOLDS`, :data:`FAILS` and :data:`NOT_COMPARABLE`. A missing number is
never replaced: the verdict is "not comparable" and its reason is the
number's own (a metric that does not apply, a method that was not run, a
failed cell).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final, Literal

from albot1.metrics.paired import BETTER, CONFIDENCE, Comparison
from albot1.report.number_text import decimals, fmt

HOLDS: Final = "holds"
FAILS: Final = "does not hold"
NOT_COMPARABLE: Final = "not comparable"
Word = Literal["holds", "does not hold", "not comparable"]


@dataclass(frozen=True)
class Number:
    """A measured number with its unit and name, or (``value`` None) why there is none."""

    label: str
    value: float | None
    unit: str = ""
    missing: str | None = None
    #: measured by a method on a dataset its preset was tuned on (:func:`albot1.report.tuning.run_held_in`);
    #: None: that method's tuning is unknown; False also for a number no run measured (a count, a threshold)
    held_in: bool | None = False

    @property
    def known(self) -> bool:
        return self.value is not None and math.isfinite(self.value)

    def text(self) -> str:
        """``0.604 m`` (3 significant digits), or ``n/a``."""
        if not self.known:
            return "n/a"
        return quantity(float(self.value), self.unit)  # type: ignore[arg-type]

    def why_missing(self) -> str:
        return f"{self.label}: {self.missing or 'no value'}"


@dataclass(frozen=True)
class Verdict:
    """A word and the numbers that decided it; ``held_in`` when one of them is held-in (:func:`held`)."""

    word: Word
    reason: str
    held_in: bool = False

    def line(self) -> str:
        return f"{self.word}: {self.reason}"


def quantity(value: float, unit: str = "") -> str:
    """``value`` to 3 significant digits with its unit (``4.61 m``, ``0.350``, ``12.0 deg``); counts as integers."""
    text = str(int(value)) if value.is_integer() and abs(value) < 1e15 else fmt(value, decimals(value))
    return f"{text} {unit}" if unit else text


def held(*numbers: Number) -> bool:
    """Whether a verdict from ``numbers`` rests on a held-in one: a claim tested on data its method was tuned on."""
    return any(n.held_in is True for n in numbers)


def _missing(*numbers: Number) -> Verdict | None:
    absent = [n for n in numbers if not n.known]
    if not absent:
        return None
    return Verdict(NOT_COMPARABLE, "; ".join(n.why_missing() for n in absent))


def _thesis(text: str | None) -> str:
    return f"; thesis {text}" if text else ""


def ratio_at_least(small: Number, large: Number, min_ratio: float, *, thesis: str | None = None) -> Verdict:
    """Holds when ``large`` is at least ``min_ratio`` times ``small`` (e.g. odometry's loop gap vs Albot1's).

    ``small`` 0 is an infinite ratio; both 0 is none (not comparable: a perfect odometry leaves no error to
    tolerate, and ``0 >= 2 * 0`` would call that a success).
    """
    absent = _missing(small, large)
    if absent is not None:
        return absent
    s, big = float(small.value), float(large.value)  # type: ignore[arg-type]
    if s == 0 and big == 0:  # 0/0: no ratio, and nothing for ``small`` to improve on
        return Verdict(
            NOT_COMPARABLE,
            f"{small.label} {small.text()} vs {large.label} {large.text()}: no ratio of two zeros, nothing to "
            f"improve on{_thesis(thesis)}",
            held(small, large),
        )
    ratio = math.inf if s == 0 else big / s
    shown = "inf" if math.isinf(ratio) else quantity(ratio)
    word: Word = HOLDS if ratio >= min_ratio else FAILS
    sense = "at least" if word == HOLDS else "below"
    return Verdict(
        word,
        f"{small.label} {small.text()} vs {large.label} {large.text()} ({shown}x, {sense} {min_ratio:g}x"
        f"{_thesis(thesis)})",
        held(small, large),
    )


def at_most(value: Number, bound: float, *, strict: bool = False, thesis: str | None = None) -> Verdict:
    """Holds when ``value`` is at most ``bound`` (below it when ``strict``)."""
    absent = _missing(value)
    if absent is not None:
        return absent
    v = float(value.value)  # type: ignore[arg-type]
    ok = v < bound if strict else v <= bound
    relation = ("<" if strict else "<=") if ok else (">=" if strict else ">")
    return Verdict(
        HOLDS if ok else FAILS,
        f"{value.label} {value.text()} {relation} {quantity(bound, value.unit)}{_thesis(thesis)}",
        held(value),
    )


def at_least(value: Number, bound: float, *, strict: bool = False, thesis: str | None = None) -> Verdict:
    """Holds when ``value`` is at least ``bound`` (above it when ``strict``)."""
    absent = _missing(value)
    if absent is not None:
        return absent
    v = float(value.value)  # type: ignore[arg-type]
    ok = v > bound if strict else v >= bound
    relation = (">" if strict else ">=") if ok else ("<=" if strict else "<")
    return Verdict(
        HOLDS if ok else FAILS,
        f"{value.label} {value.text()} {relation} {quantity(bound, value.unit)}{_thesis(thesis)}",
        held(value),
    )


def equals(value: Number, expected: float, *, thesis: str | None = None) -> Verdict:
    """Holds when ``value`` is exactly ``expected`` (counts: places, views)."""
    absent = _missing(value)
    if absent is not None:
        return absent
    ok = float(value.value) == expected  # type: ignore[arg-type]
    return Verdict(
        HOLDS if ok else FAILS,
        f"{value.label} {value.text()} {'=' if ok else '!='} {quantity(expected, value.unit)}{_thesis(thesis)}",
        held(value),
    )


def close_to(value: Number, target: float, tolerance: float, *, thesis: str | None = None) -> Verdict:
    """Holds when ``value`` is within ``tolerance`` (a fraction) of ``target``: a stand-in reproduces a setting."""
    absent = _missing(value)
    if absent is not None:
        return absent
    v = float(value.value)  # type: ignore[arg-type]
    off = abs(v - target) / abs(target) if target else math.inf
    ok = off <= tolerance
    return Verdict(
        HOLDS if ok else FAILS,
        f"{value.label} {value.text()} is {quantity(100 * off)} % from {quantity(target, value.unit)} "
        f"({'within' if ok else 'beyond'} {100 * tolerance:g} %{_thesis(thesis)})",
        held(value),
    )


def lower_than(ours: Number, theirs: Number, *, thesis: str | None = None) -> Verdict:
    """Holds when ``ours`` is strictly lower than ``theirs`` (an error, a gap)."""
    absent = _missing(ours, theirs)
    if absent is not None:
        return absent
    a, b = float(ours.value), float(theirs.value)  # type: ignore[arg-type]
    ok = a < b
    return Verdict(
        HOLDS if ok else FAILS,
        f"{ours.label} {ours.text()} {'<' if ok else '>='} {theirs.label} {theirs.text()}{_thesis(thesis)}",
        held(ours, theirs),
    )


def with_paired_test(point: Verdict, paired: Comparison) -> Verdict:
    """A "lower than" verdict (``point``) with its paired evidence: it holds only when the paired test says better.

    A mean below another is not yet "A beats B": the paired comparison of the
    two runs' errors at the same scans or relations
    (:func:`albot1.metrics.paired.compare`) must put the whole interval of
    the ratio below 1. When that test does not apply (too few pairs, errors
    not readable back from a run folder), the point comparison stands and
    the reason says that no paired test was made, and why.
    """
    if point.word == NOT_COMPARABLE:
        return point
    if not paired.applies:
        return Verdict(point.word, f"{point.reason}; no paired test ({paired.reason})", point.held_in)
    evidence = f"paired ratio {paired.text()} over {paired.pairs} pairs: {paired.verdict} at {CONFIDENCE:.0%}"
    word: Word = HOLDS if point.word == HOLDS and paired.verdict == BETTER else FAILS
    return Verdict(word, f"{point.reason}; {evidence}", point.held_in)


def all_of(verdicts: Sequence[Verdict]) -> Verdict:
    """One verdict for a claim with several parts, all of which must hold.

    A part that fails decides it (whatever the others): the claim does not
    hold. Otherwise a part that cannot be tested makes it not comparable.
    The reason lists the deciding parts: those that fail, else those not
    comparable, else all of them.
    """
    if not verdicts:
        return Verdict(NOT_COMPARABLE, "no part of the claim could be tested")
    tuned = any(v.held_in for v in verdicts)  # every part was tested, so every part's data is the claim's
    for word in (FAILS, NOT_COMPARABLE):
        deciding = [v for v in verdicts if v.word == word]
        if deciding:
            return Verdict(word, "; ".join(v.reason for v in deciding), tuned)
    return Verdict(HOLDS, "; ".join(v.reason for v in verdicts), tuned)
