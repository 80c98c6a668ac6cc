"""Albot1+'s compiled localisation (``robust_starts``) and CPython's ``math.hypot`` written out (``python_hypot``).

Bit for bit: ``python_hypot`` compiled and as written against ``math.hypot``
(edge cases, Pythagorean triples, a property test, random inputs of the
magnitudes a map holds), and ``robust_starts`` compiled against the thesis's
``localise`` then ``start_poses`` (the Python path it replaced in ``plus``).
"""

from __future__ import annotations

import math
import struct
import sys
from collections.abc import Callable, Iterator
from typing import Any

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.methods.albot1.compiled import as_written
from albot1.methods.albot1.mapping import localise_kernels
from albot1.methods.albot1.mapping.localisation import localise
from albot1.methods.albot1.mapping.localise_kernels import python_hypot, robust_starts
from albot1.methods.albot1.mapping.start_poses import ODOMETRY_TURNS, start_poses
from albot1.methods.albot1.perception.endpoints import STABLE
from albot1.methods.albot1.perception.landmarks import CORNER, OCCLUDED, OCCLUDING, UNSTABLE
from albot1.methods.albot1.perception.recognition import Tracked

#: The kernel writes out CPython 3.11's ``math.hypot`` and its left-to-right float ``sum`` (the thesis's Python
#: localisation's arithmetic on that interpreter); 3.12 sums floats with compensation, so on another interpreter the
#: kernel keeps 3.11's bits and these comparisons with the interpreter's own arithmetic do not apply.
CPYTHON_311 = pytest.mark.skipif(
    sys.version_info[:2] != (3, 11), reason="python_hypot and robust_starts reproduce CPython 3.11's arithmetic"
)


@numba.njit
def _compiled_hypot(x: float, y: float) -> float:
    return localise_kernels.python_hypot(x, y)


@numba.njit
def _compiled_hypots(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    out = np.empty(xs.shape[0])
    for i in range(xs.shape[0]):
        out[i] = localise_kernels.python_hypot(xs[i], ys[i])
    return out


@numba.njit
def _c_hypots(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    out = np.empty(xs.shape[0])
    for i in range(xs.shape[0]):
        out[i] = math.hypot(xs[i], ys[i])
    return out


def _bits(value: float) -> int:
    """The float's 64 bits (every NaN as one value: ``math.hypot`` returns a NaN, its payload is not compared)."""
    return -1 if value != value else struct.unpack("<q", struct.pack("<d", value))[0]


EDGES = [
    0.0,
    -0.0,
    5e-324,
    -5e-324,
    1e-310,
    3e-320,
    2.2250738585072014e-308,
    2.225073858507201e-308,
    1e-200,
    1e-8,
    0.1,
    1.0,
    3.0,
    4.0,
    1e8,
    1e200,
    1.3407807929942596e154,
    1.7976931348623157e308,
    -1.7976931348623157e308,
    math.inf,
    -math.inf,
    math.nan,
]


@CPYTHON_311
@pytest.mark.parametrize("fn", [_compiled_hypot, python_hypot], ids=["compiled", "as written"])
def test_python_hypot_is_math_hypot_on_zeros_subnormals_huge_and_non_finite(
    fn: Callable[[float, float], float],
) -> None:
    for x in EDGES:
        for y in EDGES:
            assert _bits(fn(x, y)) == _bits(math.hypot(x, y)), (x, y)


def test_python_hypot_of_pythagorean_triples_is_exact() -> None:
    triples = [(3, 4, 5), (5, 12, 13), (8, 15, 17), (7, 24, 25), (20, 21, 29), (119, 120, 169), (696, 697, 985)]
    for a, b, c in triples:
        for scale in (1.0, 0.25, 2.0**-40, 2.0**600, 2.0**-1070):
            for x, y in ((a, b), (b, -a), (-a, -b)):
                assert _compiled_hypot(x * scale, y * scale) == c * scale == math.hypot(x * scale, y * scale)


@CPYTHON_311
def test_python_hypot_keeps_the_bits_where_c_hypot_does_not() -> None:
    """Random landmark-sized inputs: C's ``hypot`` (numba's) differs on some, ``python_hypot`` on none."""
    rng = np.random.default_rng(24)
    n = 200_000
    xs = rng.uniform(-20.0, 20.0, n) * 10.0 ** rng.uniform(-3.0, 0.5, n)
    ys = rng.uniform(-20.0, 20.0, n) * 10.0 ** rng.uniform(-3.0, 0.5, n)
    expected = np.array([math.hypot(x, y) for x, y in zip(xs.tolist(), ys.tolist())])
    assert np.array_equal(_compiled_hypots(xs, ys).view(np.int64), expected.view(np.int64))
    assert np.count_nonzero(_c_hypots(xs, ys).view(np.int64) != expected.view(np.int64)) > 0


@CPYTHON_311
@settings(max_examples=3000, deadline=None)
@given(st.floats(allow_nan=True, allow_infinity=True), st.floats(allow_nan=True, allow_infinity=True))
def test_python_hypot_property_any_two_floats(x: float, y: float) -> None:
    assert _bits(_compiled_hypot(x, y)) == _bits(math.hypot(x, y))
    assert _bits(python_hypot(x, y)) == _bits(math.hypot(x, y))


# -- robust_starts against localise then start_poses ----------------------------------------------------------------

KINDS = [UNSTABLE, OCCLUDING, CORNER, OCCLUDED]


Rows = tuple[np.ndarray, np.ndarray, np.ndarray]


def _case(rng: np.random.Generator, k: int, fresh: bool, ties: bool) -> tuple[Tracked, Rows]:
    """``k`` recognised landmarks and a landmark map: some without a record, some ids twice, other landmarks too."""
    true = rng.uniform(-3.0, 3.0, 3)
    c, s = math.cos(true[2]), math.sin(true[2])
    surfaces = rng.uniform(-6.0, 6.0, (k, 4))
    if ties and k > 1:
        surfaces[1] = surfaces[0]  # the same length and place: equal goodness, the first wins
    kinds = rng.choice(KINDS, (k, 2)).astype(np.int64)
    ids = rng.permutation(50)[:k].astype(np.int64)
    if fresh:
        nan = np.full(k, np.nan)
        rl = Tracked(surfaces, kinds, ids, np.full(k, -1, dtype=np.int64), nan, nan, nan, nan)
    else:
        gaps = rng.uniform(0.0, 0.2, k)
        gaps[rng.random(k) < 0.2] = np.nan
        rl = Tracked(
            surfaces,
            kinds,
            ids,
            rng.integers(-1, 2, k).astype(np.int64),
            gaps,
            rng.uniform(0.0, 0.1, k),
            rng.uniform(0.0, 8.0, k),
            rng.uniform(0.0, 8.0, k),
        )
        if ties and k > 1:
            for a in (rl.side, rl.gap, rl.angle_diff, rl.prev_distance, rl.prev_distance_current):
                a[1] = a[0]
            rl.kinds[1] = rl.kinds[0]
    lm_ids: list[int] = []
    segs: list[np.ndarray] = []
    for r in rng.permutation(k):
        if rng.random() < 0.15:
            continue  # no map record: localise skips it, and so does the kernel
        seg = surfaces[r].reshape(2, 2)
        for _ in range(2 if rng.random() < 0.1 else 1):  # an id twice: the last record counts
            placed = np.column_stack([c * seg[:, 0] - s * seg[:, 1], s * seg[:, 0] + c * seg[:, 1]]) + true[:2]
            segs.append((placed + rng.normal(0.0, 0.3 if rng.random() < 0.3 else 0.01, (2, 2))).reshape(4))
            lm_ids.append(int(ids[r]))
    for other in range(50, 50 + int(rng.integers(0, 3))):  # landmarks of the map not tracked now
        segs.append(rng.uniform(-6.0, 6.0, 4))
        lm_ids.append(other)
    m = len(lm_ids)
    rows = (np.asarray(lm_ids, dtype=np.int64), np.asarray(segs).reshape(m, 4), rng.choice(KINDS, (m, 2)))
    return rl, (rows[0], rows[1], rows[2].astype(np.int64))


def _cases() -> Iterator[tuple[Tracked, Rows, int]]:
    rng = np.random.default_rng(11)
    for i in range(400):
        k = int(rng.integers(0, 9))
        yield (*_case(rng, k, fresh=i % 5 == 0, ties=i % 7 == 0), 3 if i % 3 else 2)


def _before(rl: Tracked, records: dict[int, Any]) -> tuple[np.ndarray, ...]:
    """The pose fit's landmark arrays as the mapper gathered them before the kernel (a dict of records)."""
    rows = [r for r, sid in enumerate(rl.ids.tolist()) if sid in records]
    lm_view = np.ascontiguousarray(rl.surfaces[rows], dtype=float).reshape(-1, 4)
    lm_map = np.asarray([records[int(rl.ids[r])][0] for r in rows], dtype=float).reshape(-1, 4)
    map_kinds = np.asarray([records[int(rl.ids[r])][1] for r in rows], dtype=np.int64).reshape(-1, 2)
    ok = np.ascontiguousarray(STABLE[rl.kinds[rows].reshape(-1, 2)] & STABLE[map_kinds]).reshape(-1, 2)
    return lm_view, lm_map, ok


@CPYTHON_311
@pytest.mark.parametrize("fn", [robust_starts, as_written(robust_starts)], ids=["compiled", "as written"])
def test_robust_starts_is_localise_then_start_poses(fn: Callable[..., Any]) -> None:
    chosen = none = 0
    odometry = (0.4, -1.2, 2.9)
    for rl, rows, min_candidates in _cases():
        # the mapper's dict of records (the last of an id's rows kept), as localise reads it
        records = dict(zip(rows[0].tolist(), zip(rows[1].tolist(), rows[2].tolist())))
        for view in ("previous", "current"):
            loc = localise(
                rl,
                records,
                min_candidates=min_candidates,
                gap_floor=0.01,
                angle_floor=math.radians(0.5),
                distance_view=view,
            )
            expected = start_poses(odometry, None if loc is None else loc.pose, None if loc is None else loc.poses)
            d_prev = rl.prev_distance if view == "previous" else rl.prev_distance_current
            tracked = (rl.surfaces, rl.kinds, rl.ids, rl.side, d_prev, rl.gap, rl.angle_diff)
            settings = (ODOMETRY_TURNS, min_candidates, 0.01, math.radians(0.5))
            starts, lm_view, lm_map, ok, best = fn(*tracked, *rows, *odometry, *settings)
            assert starts.shape == expected.shape and starts.flags.c_contiguous
            assert np.array_equal(starts.view(np.int64), expected.view(np.int64))
            for got, want in zip((lm_view, lm_map, ok), _before(rl, records)):
                assert got.dtype == want.dtype and got.shape == want.shape and got.flags.c_contiguous
                assert got.tobytes() == want.tobytes()  # bit for bit
            if loc is None:
                assert best == -1
                none += 1
            else:
                assert int(rl.ids[best]) == loc.reference_id
                chosen += 1
    assert chosen > 400 and none > 50


def test_robust_starts_on_a_hand_case_keeps_the_consistent_best() -> None:
    """Three landmarks agree on the pose, a fourth's map record is 2 m off: the consistent best-scored is chosen."""
    true = (1.0, 2.0, 0.3)
    c, s = math.cos(true[2]), math.sin(true[2])
    view = np.array([[-1.0, 2.0, 0.0, 2.0], [0.5, 3.0, 1.5, 3.2], [2.0, 1.0, 2.0, 2.0], [1.0, -1.0, 2.0, -1.0]])
    pts = view.reshape(-1, 2)
    placed = np.column_stack([c * pts[:, 0] - s * pts[:, 1], s * pts[:, 0] + c * pts[:, 1]]) + true[:2]
    lm_map = placed.reshape(-1, 4).copy()
    lm_map[3] += [2.0, 0.0, 2.0, 0.0]
    kinds = np.full((4, 2), OCCLUDING, dtype=np.int64)
    ids = np.array([7, 8, 9, 10])
    gaps = np.array([0.2, 0.05, 0.1, 0.001])  # the outlier scores best, landmark 8 best among the others
    ones = np.ones(4)
    # the map lists them in another order, with a landmark not seen now
    order = [3, 1, 0, 2]
    rows = (np.append(ids[order], 11), np.vstack([lm_map[order], np.zeros(4)]), np.vstack([kinds, kinds[:1]]))
    tracked = (view, kinds, ids, np.zeros(4, np.int64), ones, gaps, ones * 0.01)
    starts, lm_view, got_map, ok, best = robust_starts(*tracked, *rows, 0.5, 0.6, 0.7, ODOMETRY_TURNS, 3, 0.01, 0.001)
    assert best == 1
    assert starts.shape == (6, 3)
    assert starts[0] == pytest.approx(true, abs=1e-12)
    assert starts[1].tolist() == [0.5, 0.6, 0.7]
    assert starts[2 + 3, :2] == pytest.approx((true[0] + 2.0, true[1]), abs=1e-12)  # the outlier, dropped
    assert lm_view.tolist() == view.tolist() and got_map.tolist() == lm_map.tolist()
    assert ok.all()


def test_robust_starts_without_a_stable_landmark_turns_the_odometry() -> None:
    view = np.array([[-1.0, 2.0, 0.0, 2.0], [0.0, 1.0, 1.0, 1.0]])
    kinds = np.array([[UNSTABLE, UNSTABLE], [CORNER, CORNER]], dtype=np.int64)
    ids = np.array([3, 4])
    nan = np.full(2, np.nan)
    # landmark 4 has no record: only landmark 3's rows come back, with no stable endpoint
    tracked = (view, kinds, ids, np.full(2, -1), nan, nan, nan)
    rows = (np.array([3]), view[:1] + 1.0, kinds[:1])
    starts, lm_view, lm_map, ok, best = robust_starts(*tracked, *rows, 0.5, 0.6, 0.7, ODOMETRY_TURNS, 3, 0.01, 0.001)
    assert best == -1
    assert starts.shape == (ODOMETRY_TURNS.size, 3)
    assert starts[:, :2].tolist() == [[0.5, 0.6]] * ODOMETRY_TURNS.size
    assert np.array_equal(starts[:, 2], 0.7 + ODOMETRY_TURNS)
    assert lm_view.tolist() == view[:1].tolist() and lm_map.tolist() == (view[:1] + 1.0).tolist()
    assert ok.tolist() == [[False, False]]
