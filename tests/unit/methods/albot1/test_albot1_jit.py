"""Compiled (numba) and interpreted kernels give the same bits: per kernel, and on whole synthetic runs.

``albot1.methods.albot1.jit`` claims acceleration never changes results.
Every field of the two kernel sets (and every callee they compile) is run
both ways on inputs that reach its branches, and whole runs of the synthetic
worlds with every Albot1 preset are compared with ``accelerate`` on and off.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from albot1.data.synthetic.worlds import load_world
from albot1.geometry import se2, segments
from albot1.methods.albot1.jit import callees, kernel_compiler
from albot1.methods.albot1.mapping import pose_kernels
from albot1.methods.albot1.mapping.accel import MappingKernels, mapping_kernels
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.update import view_polygon
from albot1.methods.albot1.perception import endpoints
from albot1.methods.albot1.perception import kernels as perception_source
from albot1.methods.albot1.perception.accel import PerceptionKernels, perception_kernels
from albot1.methods.albot1.perception.landmarks import find_landmarks
from albot1.methods.albot1.perception.view import ViewParams, construct_view

numba = pytest.importorskip("numba", reason="numba is not installed: only the interpreted kernels exist")

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
    return [construct_view(r, a, PARAMS, perception_kernels(False)) for r, a in _scans()]


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
        for prior in ((0.0, 0.0, 0.0, 0.0, 0.0), (0.05, -0.02, 0.03, 400.0, 3000.0)):
            yield (starts, lm_view, lm_map, ok, points, ref, *prior, 0.05, 0.1, 0.05, 2.0, 0.5, 8)
        yield (
            starts[:1],
            lm_view[:0],
            lm_map[:0],
            ok[:0],
            points,
            ref,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.05,
            0.1,
            0.05,
            2.0,
            0.5,
            8,
        )


CASES: dict[str, Callable[[], Iterator[tuple[Any, ...]]]] = {
    "build_view": _build_view_args,
    "recognise_landmarks": _recognise_args,
    "classify_endpoints": _classify_args,
    "best_correspondence": _correspondence_args,
    "clip_parameter": _clip_args,
    "refine_pose": _refine_args,
    "resolve_partial": _partial_args,
    "scan_points": _scan_points_args,
}


def test_every_kernel_has_a_case() -> None:
    fields = [f for f in PerceptionKernels._fields + MappingKernels._fields if f != "jitted"]
    assert sorted(fields) == sorted(CASES)


@pytest.mark.parametrize("name", sorted(CASES))
def test_kernel_gives_the_same_bits_jitted_and_interpreted(name: str) -> None:
    sets = (perception_kernels, mapping_kernels)
    (fast, slow) = next((s(True), s(False)) for s in sets if name in s(True)._fields)
    assert fast.jitted and not slow.jitted
    jitted, plain = getattr(fast, name), getattr(slow, name)
    assert isinstance(jitted, numba.core.registry.CPUDispatcher) and not hasattr(plain, "py_func")
    count = 0
    for args in CASES[name]():
        assert_same_bits(jitted(*args), plain(*args))
        count += 1
    assert count >= 20


# -- the callees, compiled on their own ------------------------------------------------------------------------


def _segment_pairs() -> Iterator[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(8)
    for _ in range(300):
        yield rng.uniform(-2, 2, 4), rng.uniform(-2, 2, 4)
    a = np.array([0.0, 0.0, 2.0, 0.0])
    for b in ([1.0, -1.0, 1.0, 1.0], [1.0, 0.0, 1.0, 1.0], [3.0, 0.0, 4.0, 0.0], [1.0, 1.0, 1.0, 1.0], a):
        yield a, np.array(b)  # crossing, touching, collinear, degenerate, identical


def test_segment_geometry_gives_the_same_bits_jitted_and_interpreted() -> None:
    functions = (
        segments.segment_distance,
        segments.segments_cross,
        segments.point_segment_distance,
        segments.closest_parameter,
        segments.orientation,
        segments.line_angle,
    )
    jit = kernel_compiler(True, functions)
    for a, b in _segment_pairs():
        for fn, args in (
            (segments.segment_distance, (a, b)),
            (segments.segments_cross, (a, b)),
            (segments.point_segment_distance, (a[0], a[1], b)),
            (segments.closest_parameter, (a[0], a[1], b[0], b[1], b[2], b[3])),
            (segments.orientation, (a[0], a[1], a[2], a[3], b[0], b[1])),
            (segments.line_angle, (a[0] * 3.0 - b[1] * 5.0,)),
        ):
            assert_same_bits(jit(fn)(*args), fn(*args))


def test_wrap_and_stability_give_the_same_bits_jitted_and_interpreted() -> None:
    jit = kernel_compiler(True, (se2.wrap_angle, endpoints.is_stable))
    rng = np.random.default_rng(9)
    for a in [*rng.uniform(-20.0, 20.0, 500).tolist(), math.pi, -math.pi, 0.0, -0.0, 2 * math.pi, 1e-300]:
        assert_same_bits(jit(se2.wrap_angle)(a), se2.wrap_angle(a))
    for kind in range(4):
        assert jit(endpoints.is_stable)(kind) == endpoints.is_stable(kind)


def test_point_to_line_term_gives_the_same_bits_jitted_and_interpreted() -> None:
    """The landmark and scan terms of ``refine_pose`` share it: both Huber branches, and a degenerate normal."""
    jit = kernel_compiler(True, (pose_kernels.add_point_to_line,))
    compiled = jit(pose_kernels.add_point_to_line)
    assert compiled is not pose_kernels.add_point_to_line
    rng = np.random.default_rng(10)
    inside = outside = 0
    for _ in range(400):
        sums = tuple(rng.normal(0.0, 100.0, 9).tolist())
        angle = rng.uniform(-math.pi, math.pi)
        nx, ny = (math.cos(angle), math.sin(angle)) if rng.random() < 0.95 else (0.0, 0.0)
        ox, oy, dx, dy = rng.normal(0.0, 0.3, 4).tolist()
        threshold = float(rng.uniform(0.02, 0.4))
        args = (sums, nx, ny, ox, oy, dx, dy, float(rng.uniform(1.0, 2500.0)), threshold)
        assert_same_bits(compiled(*args), pose_kernels.add_point_to_line(*args))
        if abs(nx * ox + ny * oy) <= threshold:
            inside += 1
        else:
            outside += 1
    assert inside > 50 and outside > 50


# -- the mechanism ------------------------------------------------------------------------------------------------


def test_callees_are_found_transitively_and_compiled_with_their_caller() -> None:
    found = {fn.__name__ for fn in callees(perception_source.recognise_landmarks)}
    assert found == {"recognise_landmarks", "wrap_angle", "is_stable"}
    mapping = mapping_kernels(True)
    dispatcher: Any = mapping.best_correspondence  # a numba CPUDispatcher behind the typed field
    namespace = dispatcher.py_func.__globals__
    assert isinstance(namespace["segment_distance"], numba.core.registry.CPUDispatcher)
    # Each cache entry carries the digest of its callees' source files (numba's internals: see jit.py).
    stamp = dispatcher._cache._cache_file._source_stamp
    assert isinstance(stamp, tuple) and len(stamp[1]) == 64
    # The source modules keep their plain functions.
    assert segments.segment_distance.__module__ == "albot1.geometry.segments"
    assert not hasattr(segments.segment_distance, "py_func")


def test_without_acceleration_the_kernels_are_the_functions_as_written() -> None:
    plain = perception_kernels(False)
    assert plain.build_view is perception_source.build_view and not plain.jitted
    assert kernel_compiler(False, (se2.wrap_angle,))(se2.wrap_angle) is se2.wrap_angle


# -- whole runs ---------------------------------------------------------------------------------------------------


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


@pytest.mark.parametrize("preset", list(Albot1Mapper.presets))
def test_whole_startstop_run_is_identical_jitted_and_interpreted(preset: str) -> None:
    _assert_same_run("synthetic-office-startstop", preset)


@pytest.mark.slow
@pytest.mark.parametrize("preset", list(Albot1Mapper.presets))
def test_whole_loop_run_is_identical_jitted_and_interpreted(preset: str) -> None:
    _assert_same_run("synthetic-office-loop", preset)
