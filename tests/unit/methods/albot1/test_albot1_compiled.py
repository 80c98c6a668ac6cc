"""Compiled (numba) and as-written kernels give the same bits: per kernel, per callee, and on whole runs.

The kernels are compiled by numba's own decorators
(:mod:`albot1.methods.albot1.compiled`); their Python source is numba's
``py_func``, or the whole process with ``NUMBA_DISABLE_JIT=1``. Every kernel
is run both ways on its warm-up sample (once per kernel) and on inputs from
real scans that reach its branches; whole runs of the synthetic worlds are
compared in the ``slow`` lane (CI runs it).
"""

from __future__ import annotations

import copy
import math
import os
import re
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numba  # noqa: E402  (after the project: its cache folder is set before numba compiles)
import numpy as np
import pytest

from albot1 import versions
from albot1.data.synthetic.worlds import load_world
from albot1.geometry import se2, segments
from albot1.methods.albot1 import compiled
from albot1.methods.albot1.compiled import as_written
from albot1.methods.albot1.mapping import (
    ambiguity,
    localise_kernels,
    pose_kernels,
    screen_kernels,
    step_kernels,
    update_kernels,
)
from albot1.methods.albot1.mapping import kernels as mapping_source
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.perceptual_map import PerceptualMap
from albot1.methods.albot1.mapping.update import view_polygon
from albot1.methods.albot1.perception import endpoints
from albot1.methods.albot1.perception import kernels as perception_source
from albot1.methods.albot1.perception.kernels import PerceptionKernels
from albot1.methods.albot1.perception.landmarks import find_landmarks
from albot1.methods.albot1.perception.view import ViewParams, construct_view
from albot1.methods.albot1.places.kernels import PlacesKernels
from albot1.methods.albot1.warm_up import kernel_names, sample_calls

PARAMS = ViewParams()


def assert_same_bits(jitted: Any, plain: Any) -> None:
    """Equal values, dtypes and shapes; floats compared bit for bit (NaN in the same places)."""
    if isinstance(plain, tuple):
        assert isinstance(jitted, tuple) and len(jitted) == len(plain)
        for a, b in zip(jitted, plain):
            assert_same_bits(a, b)
        return
    a, b = np.asarray(jitted), np.asarray(plain)
    assert a.shape == b.shape
    if b.dtype.kind == "f":
        assert a.dtype == b.dtype
        assert np.array_equal(a.view(np.int64), b.view(np.int64)), f"{a} != {b}"
    else:
        assert a.dtype.kind == b.dtype.kind and np.array_equal(a, b)


def _scans() -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """REP-103 scans: every 60th frame of the loop world, plus noisy random scans with gaps."""
    for k, frame in enumerate(load_world("synthetic-office-loop")):
        if k % 60 == 0:
            yield frame.scan.ranges, frame.scan.angles
    rng = np.random.default_rng(3)
    angles = np.radians(np.arange(-90.0, 90.5, 1.0))
    for _ in range(10):
        ranges = np.abs(rng.normal(4.0, 2.0, angles.size)) + np.repeat(rng.normal(0, 1, 19), 10)[: angles.size] ** 2
        ranges[rng.random(angles.size) < 0.1] = np.nan
        yield ranges, angles


def _thesis_order(ranges: np.ndarray, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.ascontiguousarray(ranges[::-1], dtype=float), np.ascontiguousarray(angles[::-1], dtype=float)


def _views() -> list[Any]:
    return [construct_view(r, a, PARAMS, PerceptionKernels(False)) for r, a in _scans()]


# -- one generator of argument tuples per kernel ------------------------------------------------------------------


def _build_view_args() -> Iterator[tuple[Any, ...]]:
    for ranges, angles in _scans():
        r, a = _thesis_order(ranges, angles)
        yield (r, a, 30.0, 0.6, 0.2, 0.1, 0.1, math.radians(30.0), 0.0, 0.1, 0.0, 0.0, False)
        yield (r, a, 8.0, 0.3, 0.0, 0.05, 0.0, math.radians(10.0), 0.2, 0.0, 0.0, 0.0, True)
        yield (r, a, 30.0, 0.6, 0.2, 0.1, 0.1, math.radians(30.0), 0.0, 0.1, 0.15, 0.0, True)
        yield (r, a, 30.0, 0.6, 0.2, 0.1, 0.1, math.radians(30.0), 0.0, 0.1, 0.1, 2.0, False)


def _recognise_args() -> Iterator[tuple[Any, ...]]:
    lms = [find_landmarks(v, 0.4) for v in _views()]
    for prev, cur in zip(lms, lms[1:]):
        for greedy in (True, False):
            yield (prev.surfaces, prev.kinds, cur.surfaces, cur.kinds, 0.05, 0.3, 0.04, math.radians(5.0), 0.4, greedy)
            yield (prev.surfaces, prev.kinds, cur.surfaces, cur.kinds, 0.0, 0.0, 0.0, math.radians(90.0), 5.0, greedy)


def _map_inputs() -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(view polygon, view surfaces, random map segments around the view) from real views."""
    rng = np.random.default_rng(5)
    for view in _views():
        if len(view) == 0:
            continue
        surfaces = np.ascontiguousarray(view.surfaces)
        for polygon in ("robot_and_endpoints", "endpoints"):
            poly = view_polygon(surfaces, (0.0, 0.0), polygon)
            lo, hi = poly.min(axis=0) - 1.0, poly.max(axis=0) + 1.0
            segs = np.ascontiguousarray(rng.uniform(np.tile(lo, 2), np.tile(hi, 2), (40, 4)))
            yield poly, surfaces, segs


def _classify_args() -> Iterator[tuple[Any, ...]]:
    for poly, view, segs in _map_inputs():
        for surfaces_only in (True, False):
            yield (poly, view, np.ascontiguousarray(segs.reshape(-1, 2)), 0.4, surfaces_only)


def _correspondence_args() -> Iterator[tuple[Any, ...]]:
    rng = np.random.default_rng(6)
    for _, view, segs in _map_inputs():
        taken = rng.random(len(view)) < 0.2
        for seg in segs[:10]:
            yield (seg, view, taken, math.radians(5.0), 0.4)
        for seg in view[:5] + rng.normal(0.0, 0.05, (min(5, len(view)), 4)):
            yield (seg, view, np.zeros(len(view), dtype=np.bool_), math.radians(10.0), 1.0)


def _clip_args() -> Iterator[tuple[Any, ...]]:
    for poly, view, segs in _map_inputs():
        for surfaces_only in (True, False):
            for s in segs[:4]:
                yield (poly, view, float(s[0]), float(s[1]), float(s[2]), float(s[3]), 0.4, surfaces_only)


def _partial_args() -> Iterator[tuple[Any, ...]]:
    rng = np.random.default_rng(11)
    for poly, view, segs in _map_inputs():
        inside = np.ascontiguousarray(rng.random(len(segs)) < 0.5)
        taken = np.ascontiguousarray(rng.random(len(view)) < 0.2)
        near_view = np.ascontiguousarray(
            np.vstack([segs[:20], view[:6] + rng.normal(0.0, 0.05, (min(6, len(view)), 4))])
        )
        inside = np.ascontiguousarray(rng.random(len(near_view)) < 0.5)
        for clip in (True, False):
            for surfaces_only in (True, False):
                yield (near_view, inside, view, taken, poly, math.radians(5.0), 0.4, clip, 0.4, surfaces_only)


def _update_state(segs: np.ndarray, view: np.ndarray, with_robot: bool, surfaces_only: bool) -> tuple[Any, ...]:
    pmap = PerceptualMap()
    pmap.add(segs, scan=0)
    pmap.reserve(len(view), pmap.live)
    state = (pmap.seg, pmap.alive, pmap.added_at, pmap.slot_of, pmap.live_id, pmap.live_box, pmap.events)
    tail = (3, 0.4, math.radians(5.0), 0.4, False, surfaces_only)
    return (*state, pmap.n, pmap.live, pmap.n_events, view, 0.0, 0.0, with_robot, *tail)


def _update_args() -> Iterator[tuple[Any, ...]]:
    """Maps around real views, less the surfaces the update would edit: the kernel edits the map's arrays in
    place, and a map it only adds to is left so that a second call repeats the first (the edits are compared
    compiled and as written on copies in ``test_albot1_update.py``)."""
    plain = as_written(update_kernels.update_surfaces)
    for poly, view, segs in _map_inputs():
        for surfaces_only in (True, False):
            kept = segs
            for _ in range(5):
                args = _update_state(kept, view, len(poly) > 2 * len(view), surfaces_only)
                edited = np.concatenate(plain(*copy.deepcopy(args))[1:4])
                if edited.size == 0:
                    yield args
                    break
                kept = np.ascontiguousarray(np.delete(kept, edited, axis=0))


def _place_args() -> Iterator[tuple[Any, ...]]:
    rng = np.random.default_rng(12)
    for view in _views():
        theta = float(rng.uniform(-4.0, 4.0))
        yield (view.surfaces, *rng.normal(0.0, 30.0, 2).tolist(), math.cos(theta), math.sin(theta))


def _landmark_args() -> Iterator[tuple[Any, ...]]:
    for view in _views():
        for min_length in (0.0, 0.4, 1.5):
            yield (view.surfaces, view.kinds, min_length)


def test_placing_a_view_is_transform_segments_bit_for_bit() -> None:
    for surfaces, x, y, c, s in _place_args():
        theta = math.atan2(s, c)
        pose = (x, y, theta)
        expected = segments.transform_segments(pose, surfaces)
        got = mapping_source.place_segments(surfaces, x, y, math.cos(theta), math.sin(theta))
        assert_same_bits(got, expected)


def _scan_points_args() -> Iterator[tuple[Any, ...]]:
    for ranges, angles in _scans():
        for max_range, stride in ((30.0, 2), (5.0, 1), (8.0, 3)):
            yield (
                np.ascontiguousarray(ranges, dtype=float),
                np.ascontiguousarray(angles, dtype=float),
                max_range,
                stride,
            )


def _refine_args() -> Iterator[tuple[Any, ...]]:
    """Consecutive views as (current view, last update view): landmarks matched by index, points, starts, priors."""
    rng = np.random.default_rng(7)
    views = [v for v in _views() if len(v) >= 2]
    for ref_view, view in zip(views, views[1:]):
        n = min(len(ref_view), len(view), 4)
        lm_view = np.ascontiguousarray(view.surfaces[:n])
        lm_map = np.ascontiguousarray(ref_view.surfaces[:n] + rng.normal(0.0, 0.05, (n, 4)))
        ok = np.ascontiguousarray(rng.random((n, 2)) < 0.6)
        points = np.ascontiguousarray(view.surfaces.reshape(-1, 2) + rng.normal(0.0, 0.02, (2 * len(view), 2)))
        ref = np.ascontiguousarray(ref_view.surfaces)
        starts = np.ascontiguousarray(rng.normal(0.0, [0.1, 0.1, 0.05], (3, 3)))
        no_prior = (0.0, 0.0, 0.0, 0.0, 0.0)
        solver = (0.05, 0.1, 0.05, 2.0, 0.5, 8)  # line, point and scan sigmas, Huber, scan gate, iterations
        for prior in (no_prior, (0.05, -0.02, 0.03, 400.0, 3000.0)):
            yield (starts, lm_view, lm_map, ok, points, ref, *prior, *solver, math.inf)
        # The overlap rule (mapping/overlap.py) on: points beyond a surface's end are matched elsewhere or not at all.
        for overhang in (0.0, 0.1):
            yield (starts, lm_view, lm_map, ok, points, ref, *no_prior, *solver, overhang)
        yield (starts[:1], lm_view[:0], lm_map[:0], ok[:0], points, ref, *no_prior, *solver, math.inf)


def _measurement_costs_args() -> Iterator[tuple[Any, ...]]:
    """The refine cases' views, costed at their starts (the ambiguity test's fitted and predicted poses)."""
    for args in _refine_args():
        starts, lm_view, lm_map, ok, points, ref = args[:6]
        yield (starts, lm_view, lm_map, ok, points, ref, *args[11:16], args[17])


def _perceive_args() -> Iterator[tuple[Any, ...]]:
    """REP-103 beams (read-only, as the mapper passes them), view settings, landmark length, point range and stride."""
    for args in _build_view_args():
        ranges = compiled.readonly_float64(np.ascontiguousarray(args[0][::-1]))
        angles = compiled.readonly_float64(np.ascontiguousarray(args[1][::-1]))
        for tail in ((0.4, 30.0, 2), (1.5, 5.0, 1), (0.0, 8.0, 0)):
            yield (ranges, angles, *args[2:], *tail)


def _refine_and_score_args() -> Iterator[tuple[Any, ...]]:
    """``refine_pose``'s cases without their prior's information (the fused kernel fits without one)."""
    for args in _refine_args():
        yield (*args[:9], *args[11:])


def _screen_args() -> Iterator[tuple[Any, ...]]:
    """Information keeping 0 to 3 directions (scaled units, floor 400), headings across the wrap."""
    rng = np.random.default_rng(24)
    for _ in range(24):
        rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        info = np.ascontiguousarray((rotation * 10.0 ** rng.uniform(1.0, 5.0, 3)) @ rotation.T)
        heading = float(rng.uniform(-math.pi, math.pi))
        yield (0.1, -0.2, heading, info, 0.05, -0.1, -heading, 0.4, 400.0)


def _robust_starts_args() -> Iterator[tuple[Any, ...]]:
    """Recognised landmarks with every endpoint label, matched or fresh (NaN match data), some outliers, ties,
    some without a map record, some ids twice in the map."""
    rng = np.random.default_rng(6)
    turns = np.radians(np.arange(-30.0, 31.0, 10.0))
    for i in range(60):
        k = i % 9
        view = rng.uniform(-6.0, 6.0, (k, 4))
        ids = rng.permutation(20)[:k].astype(np.int64)
        lm_map = view + rng.normal(0.0, 0.5 if i % 4 == 0 else 0.01, (k, 4)) + rng.uniform(-1.0, 1.0, 4)
        if i % 6 == 0 and k > 1:
            view[1], lm_map[1] = view[0], lm_map[0]  # a tie: the first candidate wins
        match = rng.uniform(0.0, 0.2, (3, k))
        match[rng.random((3, k)) < (1.0 if i % 5 == 0 else 0.2)] = np.nan
        sides = np.full(k, -1, dtype=np.int64) if i % 5 == 0 else rng.integers(-1, 2, k).astype(np.int64)
        kinds = rng.integers(0, 4, (2, k, 2)).astype(np.int64)
        d_prev, gaps, angle_diffs = (np.ascontiguousarray(row) for row in match)
        recorded = rng.permutation(k)[: k - i % 2]  # an odd case leaves one landmark without its record
        lm_ids = np.concatenate([ids[recorded], ids[recorded[:1]]])  # one id twice: its last row counts
        lm_rows = np.concatenate([lm_map[recorded], lm_map[recorded[:1]] + 0.5])
        lm_kinds = np.concatenate([kinds[1][recorded], kinds[1][recorded[:1]]])
        tracked = (view, kinds[0], ids, sides, d_prev, gaps, angle_diffs)
        yield (*tracked, lm_ids, lm_rows, lm_kinds, 0.3, -0.2, 1.0, turns, 2 + i % 3, 0.01, 0.002)


CASES: dict[str, Callable[[], Iterator[tuple[Any, ...]]]] = {
    "build_view": _build_view_args,
    "recognise_landmarks": _recognise_args,
    "classify_endpoints": _classify_args,
    "best_correspondence": _correspondence_args,
    "clip_parameter": _clip_args,
    "refine_pose": _refine_args,
    "resolve_partial": _partial_args,
    "update_surfaces": _update_args,
    "place_segments": _place_args,
    "landmark_rows": _landmark_args,
    "scan_points": _scan_points_args,
    "measurement_costs": _measurement_costs_args,
    "screen_directions": _screen_args,
    "perceive": _perceive_args,
    "refine_and_score": _refine_and_score_args,
    "robust_starts": _robust_starts_args,
}


#: the kernels by name, as compiled (module attributes: numba dispatchers)
KERNELS: dict[str, Any] = {
    **{name: getattr(perception_source, name) for name in ("build_view", "recognise_landmarks", "landmark_rows")},
    **{
        name: getattr(mapping_source, name)
        for name in (
            "classify_endpoints",
            "best_correspondence",
            "clip_parameter",
            "resolve_partial",
            "place_segments",
        )
    },
    "update_surfaces": update_kernels.update_surfaces,
    **{name: getattr(pose_kernels, name) for name in ("refine_pose", "scan_points")},
    "measurement_costs": ambiguity.measurement_costs,
    "screen_directions": screen_kernels.screen_directions,
    **{name: getattr(step_kernels, name) for name in ("perceive", "refine_and_score")},
    "robust_starts": localise_kernels.robust_starts,
}


def _all_sets(compiled: bool = True) -> tuple[Any, ...]:
    return PerceptionKernels(compiled), MappingKernels(compiled), PlacesKernels(compiled)


def test_every_kernel_has_a_case() -> None:
    assert sorted(CASES) == sorted(KERNELS)
    called = {name for s in (PerceptionKernels(), MappingKernels()) for name in kernel_names(s)}
    assert called <= set(KERNELS)


@pytest.mark.parametrize("name", sorted(CASES))
def test_kernel_gives_the_same_bits_compiled_and_as_written(name: str) -> None:
    jitted = KERNELS[name]
    plain = as_written(jitted)
    assert isinstance(jitted, numba.core.registry.CPUDispatcher) and not hasattr(plain, "py_func")
    count = 0
    for args in CASES[name]():
        assert_same_bits(jitted(*args), plain(*args))
        count += 1
    assert count >= 20


def test_every_kernel_a_mapper_calls_has_a_warm_up_sample() -> None:
    names = [name for s in _all_sets() for name in kernel_names(s)]
    assert sorted(names) == sorted({name for name, _, _ in sample_calls(*_all_sets())})


@pytest.mark.parametrize("name", sorted(name for s in _all_sets() for name in kernel_names(s)))
def test_kernel_sample_gives_the_same_bits_compiled_and_as_written(name: str) -> None:
    """Once per kernel, on its warm-up sample: the parity lane of the places kernels too."""
    calls = [(fast, args) for n, fast, args in sample_calls(*_all_sets()) if n == name]
    slow = [plain for n, plain, _ in sample_calls(*_all_sets(compiled=False)) if n == name]
    assert calls and len(calls) == len(slow)
    for (fast, args), plain in zip(calls, slow):
        assert isinstance(fast, numba.core.registry.CPUDispatcher) and plain is fast.py_func
        assert_same_bits(fast(*args), plain(*args))


# -- the fused kernels (step_kernels) against the pieces they call, as written ------------------------------------
# Their own Python source calls the compiled pieces, so the parity above does not reach the pieces' source: here the
# compiled fused kernel meets the pieces' Python source, called as the mapper called them before the fusion.


def _perceive_by_pieces(*args: Any) -> tuple[Any, ...]:
    ranges, angles, stride = args[0], args[1], args[15]
    view = as_written(perception_source.build_view)(*_thesis_order(ranges, angles), *args[2:13])
    rows = as_written(perception_source.landmark_rows)(view[0], view[1], args[13])
    points = as_written(pose_kernels.scan_points)(ranges, angles, args[14], stride) if stride > 0 else np.empty((0, 2))
    return (*view, *rows, points)


def test_perceive_is_build_view_landmark_rows_and_scan_points_as_written() -> None:
    cases = list(_perceive_args())
    assert len(cases) >= 20 and any(args[15] == 0 for args in cases)
    for args in cases:
        assert_same_bits(step_kernels.perceive(*args), _perceive_by_pieces(*args))


def _landmark_arrays(landmarks: Any) -> tuple[Any, ...]:
    return (landmarks.index, landmarks.surfaces, landmarks.kinds)


def test_perceive_scan_holds_construct_view_s_view_and_find_landmarks_landmarks() -> None:
    plain = PerceptionKernels(False)
    for ranges, angles in _scans():
        for params in (PARAMS, ViewParams(fit_lines=True, end_spacing_max=0.15)):
            view, lms, points = step_kernels.perceive_scan(ranges, angles, params, 0.4, 30.0, 0)
            expected = construct_view(ranges, angles, params, plain)
            landmarks = find_landmarks(expected, 0.4, plain)
            assert_same_bits(
                (view.surfaces, view.kinds, view.beams, view.cluster, lms.index, lms.surfaces, lms.kinds),
                (expected.surfaces, expected.kinds, expected.beams, expected.cluster, *_landmark_arrays(landmarks)),
            )
            assert points.shape == (0, 2)


def test_perceive_scan_on_degenerate_scans_does_what_the_pieces_do() -> None:
    """No beam, no finite beam, every beam out of range: the same (empty) view and landmarks, or the same error."""
    plain = PerceptionKernels(False)
    angles = np.radians(np.arange(-90.0, 90.5, 1.0))
    for ranges, beams in (
        (np.empty(0), np.empty(0)),
        (np.full(angles.size, np.nan), angles),
        (np.full(angles.size, 50.0), angles),
    ):
        try:
            expected = construct_view(ranges, beams, PARAMS, plain)
            landmarks = find_landmarks(expected, 0.4, plain)
        except Exception as error:  # noqa: BLE001 (whatever the pieces raise, the fused call must raise too)
            with pytest.raises(type(error), match=re.escape(str(error))):
                step_kernels.perceive_scan(ranges, beams, PARAMS, 0.4, 30.0, 1)
            continue
        view, lms, points = step_kernels.perceive_scan(ranges, beams, PARAMS, 0.4, 30.0, 1)
        assert_same_bits(
            (view.surfaces, view.kinds, view.beams, view.cluster, lms.index, lms.surfaces, lms.kinds),
            (expected.surfaces, expected.kinds, expected.beams, expected.cluster, *_landmark_arrays(landmarks)),
        )
        assert len(view.surfaces) == 0 and points.shape[1] == 2


def test_refine_and_score_is_refine_pose_then_measurement_costs_as_written() -> None:
    refine, costs_of = as_written(pose_kernels.refine_pose), as_written(ambiguity.measurement_costs)
    cases = list(_refine_and_score_args())
    assert len(cases) >= 20
    for args in cases:
        arrays, prior, solver = args[:6], args[6:9], args[9:]
        x, y, phi, info = refine(*arrays, *prior, 0.0, 0.0, *solver)
        poses = np.array([(x, y, phi), prior], dtype=float)  # as view_ambiguity builds them
        costs, _, matched, terms, independent = costs_of(poses, *arrays[1:], *solver[:5], solver[6])
        expected = (x, y, phi, info, float(costs[0]), float(costs[1]), float(matched), int(terms), int(independent))
        assert_same_bits(step_kernels.refine_and_score(*args), expected)


# -- the callees, compiled on their own ------------------------------------------------------------------------


def _segment_pairs() -> Iterator[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(8)
    for _ in range(300):
        yield rng.uniform(-2, 2, 4), rng.uniform(-2, 2, 4)
    a = np.array([0.0, 0.0, 2.0, 0.0])
    for b in ([1.0, -1.0, 1.0, 1.0], [1.0, 0.0, 1.0, 1.0], [3.0, 0.0, 4.0, 0.0], [1.0, 1.0, 1.0, 1.0], a):
        yield a, np.array(b)  # crossing, touching, collinear, degenerate, identical


def test_segment_geometry_gives_the_same_bits_compiled_and_as_written() -> None:
    functions = (
        segments.segment_distance,
        segments.segments_cross,
        segments.point_segment_distance,
        segments.closest_parameter,
        segments.orientation,
        segments.line_angle,
    )
    jit = {fn: numba.njit(fn) for fn in functions}  # compiled the way a kernel compiles its callees
    for a, b in _segment_pairs():
        for fn, args in (
            (segments.segment_distance, (a, b)),
            (segments.segments_cross, (a, b)),
            (segments.point_segment_distance, (a[0], a[1], b)),
            (segments.closest_parameter, (a[0], a[1], b[0], b[1], b[2], b[3])),
            (segments.orientation, (a[0], a[1], a[2], a[3], b[0], b[1])),
            (segments.line_angle, (a[0] * 3.0 - b[1] * 5.0,)),
        ):
            assert_same_bits(jit[fn](*args), fn(*args))


def test_wrap_and_stability_give_the_same_bits_compiled_and_as_written() -> None:
    wrap, stable = numba.njit(se2.wrap_angle), numba.njit(endpoints.is_stable)
    rng = np.random.default_rng(9)
    for a in [*rng.uniform(-20.0, 20.0, 500).tolist(), math.pi, -math.pi, 0.0, -0.0, 2 * math.pi, 1e-300]:
        assert_same_bits(wrap(a), se2.wrap_angle(a))
    for kind in range(4):
        assert stable(kind) == endpoints.is_stable(kind)


def test_point_to_line_term_gives_the_same_bits_compiled_and_as_written() -> None:
    """The landmark and scan terms of ``refine_pose`` share it: both Huber branches, and a degenerate normal."""
    jitted = numba.njit(pose_kernels.add_point_to_line)
    rng = np.random.default_rng(10)
    inside = outside = 0
    for _ in range(400):
        sums = tuple(rng.normal(0.0, 100.0, 9).tolist())
        angle = rng.uniform(-math.pi, math.pi)
        nx, ny = (math.cos(angle), math.sin(angle)) if rng.random() < 0.95 else (0.0, 0.0)
        ox, oy, dx, dy = rng.normal(0.0, 0.3, 4).tolist()
        threshold = float(rng.uniform(0.02, 0.4))
        args = (sums, nx, ny, ox, oy, dx, dy, float(rng.uniform(1.0, 2500.0)), threshold)
        assert_same_bits(jitted(*args), pose_kernels.add_point_to_line(*args))
        if abs(nx * ox + ny * oy) <= threshold:
            inside += 1
        else:
            outside += 1
    assert inside > 50 and outside > 50


# -- the mechanism ------------------------------------------------------------------------------------------------


def _python(code: str, **env: str) -> str:
    """Run ``code`` in a fresh interpreter (this environment plus ``env``); its stdout."""
    out = subprocess.run(
        [sys.executable, "-c", code], env={**os.environ, **env}, capture_output=True, text=True, timeout=600
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_callees_stay_plain_functions_and_the_geometry_layer_does_not_import_numba() -> None:
    assert not hasattr(segments.segment_distance, "py_func") and not hasattr(se2.wrap_angle, "py_func")
    assert not hasattr(pose_kernels.add_point_to_line, "py_func")
    assert _python("import sys, albot1.geometry.segments, albot1.data.model; print('numba' in sys.modules)") == (
        "False\n"
    )


def test_kernels_are_cached_in_a_folder_named_by_the_code_version() -> None:
    assert compiled.CACHE_DIR.name == versions.code_version()
    assert os.environ["NUMBA_CACHE_DIR"] == str(compiled.CACHE_DIR)
    PerceptionKernels().build_view(
        *next(args for name, _, args in sample_calls(PerceptionKernels()) if name == "build_view")
    )
    assert compiled.is_cached() and any(compiled.CACHE_DIR.rglob("kernels.build_view-*.nbi"))


@pytest.mark.slow
@pytest.mark.compile
def test_an_unwritable_user_cache_falls_back_to_a_per_user_temporary_folder() -> None:
    """As for an installed wheel whose user cache cannot be written: numba still caches, elsewhere."""
    code = (
        "import tempfile\n"
        "from albot1.methods.albot1 import compiled\n"
        "from albot1.methods.albot1.places.kernels import PlacesKernels\n"
        "from albot1.methods.albot1.warm_up import sample_calls\n"
        "for name, kernel, args in sample_calls(PlacesKernels()):\n"
        "    if name == 'same_any':\n"
        "        kernel(*args)\n"
        "print(compiled.CACHE_DIR.is_relative_to(tempfile.gettempdir()), compiled.is_cached())\n"
    )
    assert _python(code, XDG_CACHE_HOME="/proc/albot1-cannot-write-here").split() == ["True", "True"]


def test_without_acceleration_a_mapper_calls_the_kernels_as_written() -> None:
    plain = PerceptionKernels(False)
    assert not plain.compiled and plain.build_view is perception_source.build_view.py_func
    assert PlacesKernels(False).match_structure is as_written(PlacesKernels().match_structure)


@pytest.mark.slow
@pytest.mark.compile
def test_numba_s_switch_runs_every_kernel_as_written_with_the_same_results() -> None:
    """``NUMBA_DISABLE_JIT=1``: the decorators hand back the functions; a short run gives the same bits."""
    code = (
        "from albot1.methods.albot1.perception import kernels\n"
        "print(type(kernels.build_view).__name__)\n"
        f"{_FINGERPRINT}\n"
        "print(fingerprint('albot1', 'plus', 'synthetic-office-startstop', 40))\n"
    )
    kind, fingerprint = _python(code, NUMBA_DISABLE_JIT="1").split()
    assert kind == "function"
    assert fingerprint == _fingerprint("albot1", "plus", "synthetic-office-startstop", 40)


# -- whole runs ---------------------------------------------------------------------------------------------------

#: source of ``fingerprint(method, preset, world, limit)``: sha256 of a run's poses, map and counters
_FINGERPRINT = """
import hashlib, json
import numpy as np
from albot1.data.synthetic.worlds import load_world
from albot1.methods.registry import get_method, resolve_config

def fingerprint(method, preset, world, limit):
    mapper = get_method(method).load_class()(resolve_config(method, preset, None))
    for k, frame in enumerate(load_world(world)):
        if k == limit:
            break
        mapper.process(frame)
    out = mapper.finish()
    digest = hashlib.sha256(np.ascontiguousarray(out.poses).tobytes())
    digest.update(np.ascontiguousarray(out.map.segments).tobytes())
    digest.update(json.dumps(out.counters, sort_keys=True).encode())
    return digest.hexdigest()
"""
_namespace: dict[str, Any] = {}
exec(_FINGERPRINT, _namespace)
_fingerprint: Callable[[str, str, str, int | None], str] = _namespace["fingerprint"]


def _run(world: str, preset: str, accelerate: bool) -> Any:
    config = Albot1Config.model_validate({**Albot1Mapper.presets[preset], "accelerate": accelerate})
    mapper = Albot1Mapper(config)
    for frame in load_world(world):
        mapper.process(frame)
    return mapper.finish()


def _assert_same_run(world: str, preset: str) -> None:
    fast, slow = _run(world, preset, True), _run(world, preset, False)
    assert_same_bits(fast.poses, slow.poses)
    assert_same_bits(fast.map.segments, slow.map.segments)
    assert fast.map.segment_properties == slow.map.segment_properties
    assert fast.counters == slow.counters
    assert fast.extras == slow.extras


def _distinct_presets() -> list[str]:
    """One preset name per distinct configuration: ``thesis`` is ``default`` (an empty preset), run once, not twice."""
    seen: dict[str, str] = {}
    for name in Albot1Mapper.presets:
        key = Albot1Config.model_validate(Albot1Mapper.presets[name]).model_dump_json()
        seen.setdefault(key, name)
    return list(seen.values())


def test_identical_presets_are_run_once() -> None:
    """The whole-run parity covers every distinct preset configuration, each once."""
    configs = {name: Albot1Config.model_validate(v).model_dump_json() for name, v in Albot1Mapper.presets.items()}
    distinct = _distinct_presets()
    assert set(configs.values()) == {configs[name] for name in distinct}
    assert len(distinct) == len(set(configs.values()))


@pytest.mark.slow
@pytest.mark.parametrize("preset", _distinct_presets())
@pytest.mark.whole_log
def test_whole_startstop_run_is_identical_compiled_and_as_written(preset: str) -> None:
    _assert_same_run("synthetic-office-startstop", preset)


@pytest.mark.slow
@pytest.mark.parametrize("preset", _distinct_presets())
@pytest.mark.whole_log
def test_whole_loop_run_is_identical_compiled_and_as_written(preset: str) -> None:
    _assert_same_run("synthetic-office-loop", preset)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["albot1", "albot1-places"])
@pytest.mark.whole_log
def test_whole_loop_run_is_identical_with_numba_s_switch(method: str) -> None:
    """Every kernel and callee as Python, process-wide (``NUMBA_DISABLE_JIT=1``), against the compiled run."""
    code = f"{_FINGERPRINT}\nprint(fingerprint({method!r}, 'default', 'synthetic-office-loop', None))\n"
    as_written = _python(code, NUMBA_DISABLE_JIT="1").strip()
    assert as_written == _fingerprint(method, "default", "synthetic-office-loop", None)


def _stand_in_kernel() -> None:
    """A function standing in for a kernel's Python source in the cache-lookup test."""


def test_a_kernel_is_cached_only_in_its_own_source_folder_of_the_cache(tmp_path: Path) -> None:
    # Two checkouts of one code version share the version's folder, each with its own numba subfolder: another
    # checkout's index must not count, or a warm-up skips the parallel compile of a kernel that is in fact cold.
    from types import SimpleNamespace

    own, other = tmp_path / "mapping_own", tmp_path / "mapping_other"
    own.mkdir()
    other.mkdir()
    kernel = SimpleNamespace(py_func=_stand_in_kernel, _cache=SimpleNamespace(cache_path=str(own)))
    index = f"{Path(__file__).stem}._stand_in_kernel-123.py311.nbi"
    (other / index).write_bytes(b"")
    assert not compiled.is_cached(kernel)
    (own / index).write_bytes(b"")
    assert compiled.is_cached(kernel)
