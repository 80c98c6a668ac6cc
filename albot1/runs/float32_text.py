"""float32 values as numpy writes them (shortest round-trip digits), by integer arithmetic on whole arrays.

``map.geojson`` holds a point map's float32 coordinates in the text ``astype(StringDType())`` gives them:
numpy's Dragon4 in its shortest ("unique") mode, about 0.5 us a value, which made writing the file the largest
single part of an odometry cell on a long log (1.0 of ~3 CPU-s on fr-clinic, 1,011,528 values;
docs/benchmarking.md, "Session 26: the cell cost that grows with the log"). :func:`float32_fields` gives the
same text for the values in :func:`in_fast_range` (zero and 1e-4 < |x| < 1e6, where numpy writes every
value in positional notation: every coordinate of a map in metres but the tiniest) and hands the rest to numpy.

Dragon4's choice, restated in integers: with ``x = m * 2**e`` (``m`` the 24-bit significand), the values that
read back as ``x`` lie strictly inside ``(x - lo, x + hi)``, ``hi = 2**(e-1)`` and ``lo = hi``, or ``hi / 2``
where ``m`` is a power of two (the float below is nearer). Going from the coarsest decimal place to finer ones,
Dragon4 stops at the first place ``10**p`` where the multiple of it just below ``x`` or the one just above lies
inside; it takes the one inside, or the nearer when both are (the even digit at an exact tie). All of it is
exact in uint64 once the value is scaled by ``10**J * 2**(J' + 2)`` (``J`` decimals, ``J' = -(e + J)``):
``x`` is ``4 m 5**J`` (below 2**59 in range), the margins ``2 * 5**J`` and ``5**J``, the place ``10**t * 2**(J'+2)``.
Whether numpy's margins are open or closed and how it breaks ties never matters in range: below 2**22 no
midpoint between two float32 is a decimal of 9 significant digits or fewer (it has more decimals than that),
and no float32 lies midway between two such decimals. ``benchmarks/float32_text_exhaustive.py`` compares
every float32 of the range, both signs, with numpy's text (identical, docs/benchmarking.md "Session 26");
``tests/unit/runs/test_float32_text.py`` compares whole binades, their edges and the decimal boundaries.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["FIELD", "field_texts", "float32_fields", "in_fast_range"]

#: Bounds of the range written here (numpy's own positional range for float32 text is [1e-4, 1e6)).
LOW = np.float32(1e-4)
HIGH = np.float32(1e6)
#: Decimal places a candidate can sit at, relative to J: 10**(E+1) (a carry: 0.099999994 -> 0.1) to 10**(E-9).
_PLACES = 11
_POW10 = 10 ** np.arange(20, dtype=np.uint64)
_POW5 = 5 ** np.arange(20, dtype=np.uint64)
#: Characters of a value's row: sign, up to 7 digits before the point (6 below 1e6), the point, up to 14 decimals
#: (13 at 9 significant digits from 1e-4; one more where log10 misjudges the leading digit); ``slow``'s texts
#: (``repr`` of a float64 read from a float32's digits) take at most 19.
_WHOLE_DIGITS = 7
_FRACTION_DIGITS = 14
#: Digits of ``digits * 10**-decimals`` (below 10**11: at most 9 significant digits, one place of slack).
_DIGITS = 11
FIELD = 24


def in_fast_range(values: NDArray[np.float32]) -> NDArray[np.bool_]:
    """Which of ``values`` :func:`float32_fields` writes itself (the rest go to the caller's ``slow`` text)."""
    size = np.abs(np.asarray(values, dtype=np.float32))
    inside: NDArray[np.bool_] = (size == 0) | ((size > LOW) & (size < HIGH))
    return inside


def float32_fields(values: NDArray[np.float32], slow: Callable[[NDArray[np.float32]], list[str]]) -> NDArray[np.uint8]:
    """The text of each of ``values`` (1-D float32) as ASCII bytes, one row of :data:`FIELD` per value.

    A row holds the value's characters in order with NUL bytes between or after them (``row[row != 0]`` is the
    text): the rows of a whole map are joined by one boolean compress, never by Python strings. Values in
    :func:`in_fast_range` are written here; ``slow`` gives the text of the others (the caller's own notation).
    """
    values = np.asarray(values, dtype=np.float32).reshape(-1)
    out = np.zeros((len(values), FIELD), dtype=np.uint8)
    fast = np.flatnonzero(in_fast_range(values))
    digits, decimals, done = _decimal(values[fast])
    written = fast[done]
    out[written] = _positional_fields(values[written], digits[done], decimals[done])
    rest = np.ones(len(values), dtype=np.bool_)
    rest[written] = False
    if rest.any():
        texts = slow(values[rest])
        longest = max(texts, key=len)
        if len(longest) > FIELD:
            raise ValueError(f"float32 text {longest!r} is longer than a field ({FIELD} characters)")
        out[rest] = np.array(texts, dtype=f"S{FIELD}").view(np.uint8).reshape(-1, FIELD)
    return out


def field_texts(fields: NDArray[np.uint8]) -> list[str]:
    """The text of each row of :func:`float32_fields` (for tests and messages: a Python string per value)."""
    return [row[row != 0].tobytes().decode("ascii") for row in fields]


def _decimal(values: NDArray[np.float32]) -> tuple[NDArray[np.uint64], NDArray[np.int64], NDArray[np.bool_]]:
    """Dragon4's shortest decimal of each in-range value, as ``digits * 10**-decimals`` of ``|value|``, and for
    which values one was found (all, by the tests; any other is left to the caller's slow path)."""
    bits = values.view(np.uint32)
    exponent_bits = ((bits >> np.uint32(23)) & np.uint32(0xFF)).astype(np.int64)
    fraction = (bits & np.uint32(0x7FFFFF)).astype(np.uint64)
    zero = exponent_bits == 0  # in range only +-0 have a zero exponent field (subnormals are below 1e-4)
    m = fraction | np.uint64(1 << 23)
    e = exponent_bits - 150
    size = np.abs(values.astype(np.float64))
    with np.errstate(divide="ignore"):
        first = np.floor(np.log10(np.where(zero, 1.0, size))).astype(np.int64)  # E, or one off: still exact
    decimals = 9 - first  # J: 4 (below 1e6) to 13 (from 1e-4) decimals, one more or less where E is one off
    shift = np.where(zero, 0, 2 - (e + decimals))  # J' + 2 >= 2 in range
    five = _POW5[decimals]
    scaled = (m << np.uint64(2)) * five
    high = five << np.uint64(1)
    low = np.where(fraction == 0, five, high)
    # A place 10**t holds a candidate when a multiple of 10**t lies in (a, b], a and b the integers (in units of
    # 10**-J; ``>> shift`` rounds down exactly) just below the interval and last inside it: when a and b differ
    # at or above digit t. floor(log10(b - a)) holds one (or the place below it, where log10 rounded up); the
    # place above holds at most one, c, and then the coarsest place is c's last non-zero digit.
    u64 = shift.astype(np.uint64)
    a = (scaled - low) >> u64
    b = (scaled + high - np.uint64(1)) >> u64
    width = np.maximum(b - a, np.uint64(1)).astype(np.float64)
    place = np.clip(np.floor(np.log10(width)).astype(np.int64), 0, _PLACES - 1)
    place -= (place > 0) & (b // _POW10[place] == a // _POW10[place])
    up = np.minimum(place + 1, _PLACES - 1)
    climbs = np.flatnonzero((up > place) & (b // _POW10[up] > a // _POW10[up]))
    if len(climbs):
        t = up[climbs]
        c = b[climbs] // _POW10[t]  # the one multiple of 10**t in (a, b], over 10**t
        for _ in range(_PLACES):
            more = (t < _PLACES - 1) & (c % np.uint64(10) == 0) & (c > 0)
            if not more.any():
                break
            t = t + more
            c = np.where(more, c // np.uint64(10), c)
        place[climbs] = t
    done = zero | (b // _POW10[place] > a // _POW10[place])
    step = _POW10[place] << u64
    below = (scaled // step) * step
    above = below + step
    low_ok = scaled - below < low
    high_ok = above - scaled < high
    rest = (scaled - below) << np.uint64(1)
    even = ((below // step) & np.uint64(1)) == 0
    down = low_ok & (~high_ok | (rest < step) | ((rest == step) & even))
    chosen = np.where(zero, np.uint64(0), np.where(down, below, above))
    done &= zero | low_ok | high_ok
    return chosen >> u64, decimals, done  # the decimal value times 10**J


def _positional_fields(
    values: NDArray[np.float32], digits: NDArray[np.uint64], decimals: NDArray[np.int64]
) -> NDArray[np.uint8]:
    """Rows of :func:`float32_fields` for ``[-]I.F``: ``digits * 10**-decimals``, I without leading zeros, F
    without trailing ones, each at least one digit (``0.5``, ``100.0``, ``-0.0``) as numpy writes them.

    Values are taken a number of decimals at a time (a handful of groups), so every division is by a constant
    and every digit lands in a fixed column: slots 1-7 hold the places 10**6 .. 10**0, slot 8 the point, slots
    9-22 the places 10**-1 .. 10**-14.
    """
    rows = np.zeros((len(values), FIELD), dtype=np.uint8)
    rows[:, 0] = np.where(np.signbit(values), ord("-"), 0)
    rows[:, _WHOLE_DIGITS + 1] = ord(".")
    ten, zero_character = np.uint64(10), np.uint8(ord("0"))
    for count in np.unique(decimals).tolist():
        group = np.flatnonzero(decimals == count)
        block = rows[group]
        rest = digits[group]
        seen = np.zeros(len(group), dtype=np.bool_)  # a non-zero decimal at or right of this place
        for power in range(_DIGITS):  # right to left: the digit of 10**power is that of place power - count
            place = power - count
            present = rest > 0  # the number reaches this digit (places left of the units)
            rest, digit = np.divmod(rest, ten)
            if place < -_FRACTION_DIGITS or place >= _WHOLE_DIGITS:
                continue
            if place < 0:
                seen |= digit != 0
                shown = seen if place < -1 else np.ones(len(group), dtype=np.bool_)
                slot = _WHOLE_DIGITS + 1 - place
            else:
                shown = present if place > 0 else np.ones(len(group), dtype=np.bool_)
                slot = _WHOLE_DIGITS - place
            block[:, slot] = np.where(shown, digit.astype(np.uint8) + zero_character, np.uint8(0))
        for place in range(min(_DIGITS - count, 1), 0):  # left of the number's first digit: 0.00x
            block[:, _WHOLE_DIGITS + 1 - place] = np.where(seen | (place == -1), zero_character, np.uint8(0))
        if _DIGITS - count <= 0:  # the units too: 0.x
            block[:, _WHOLE_DIGITS] = zero_character
        rows[group] = block
    return rows
