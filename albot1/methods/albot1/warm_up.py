"""One small call per kernel, so numba compiles (or loads from its cache) every kernel before the first scan.

Numba compiles a kernel for the argument types of its first call. The
mappers call each kernel with one set of types (dtype, dimensions, layout,
read-only flag), so one small call per kernel with those types, made by
:func:`warm_up` before a run's timed loop, leaves nothing to compile during
the scans (a test checks that whole runs after a warm-up compile nothing
new). The same calls are the parity tests' small inputs: each kernel run
compiled and as written gives the same bits.

Changing a kernel's argument types means changing its sample here; the
tests name the kernel whose sample no longer fits.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.methods.albot1 import compiled


def kernel_names(kernels: object) -> list[str]:
    """The kernels a kernel set (``PerceptionKernels``, ...) holds: its attributes other than ``compiled``."""
    return [name for name in vars(kernels) if name != "compiled"]


def _readonly(a: NDArray[Any]) -> NDArray[Any]:
    a = np.array(a)
    a.flags.writeable = False
    return a


def _update_sample(seg: NDArray[np.float64]) -> tuple[Any, ...]:
    """A two-surface map and a view far from it: only additions, so a second call repeats the first exactly."""
    cap = 8
    box = np.zeros((cap, 4))
    box[:2] = np.column_stack(
        [seg[:, [0, 2]].min(1), seg[:, [1, 3]].min(1), seg[:, [0, 2]].max(1), seg[:, [1, 3]].max(1)]
    )
    state = (np.resize(seg, (cap, 4)), np.arange(cap) < 2, np.zeros(cap, dtype=np.int64))
    slots = (np.where(np.arange(cap) < 2, np.arange(cap), -1), np.arange(cap, dtype=np.int64), box)
    view = seg + 20.0
    log = np.zeros((cap, 3), dtype=np.int64)
    return (*state, *slots, log, 2, 2, 0, view, 20.0, 20.0, True, 1, 0.4, 0.1, 0.4, True, True)


def _samples() -> dict[str, list[tuple[Any, ...]]]:
    """Argument tuples per kernel name, typed as the mappers call them (scan arrays may be read-only)."""
    angles = np.radians(np.arange(90.0, -90.5, -10.0))
    ranges = 3.0 + 0.5 * np.cos(3.0 * angles)
    ranges[5] = np.nan
    seg = np.array([[-1.0, 2.0, 0.0, 2.5], [0.2, 2.5, 1.5, 2.0]])
    kinds = np.array([[1, 2], [2, 1]], dtype=np.int64)
    ids = np.arange(2, dtype=np.int64)
    poly = np.array([[0.0, 0.0], [-3.0, 3.0], [3.0, 3.0]])
    points = np.ascontiguousarray(seg.reshape(-1, 2))
    taken = np.zeros(2, dtype=np.bool_)
    starts = np.zeros((1, 3))
    ok = np.ones((2, 2), dtype=np.bool_)
    scan_angles = np.radians(np.arange(-90.0, 90.5, 10.0))
    scan_ranges = np.full(scan_angles.size, 2.5)
    return {
        "build_view": [(ranges, angles, 30.0, 0.6, 0.2, 0.1, 0.1, math.radians(30.0), 0.0, 0.1, 0.0, 0.0, False)],
        "recognise_landmarks": [(seg, kinds, seg + 0.01, kinds, 0.05, 0.3, 0.04, math.radians(5.0), 0.4, True)],
        "classify_endpoints": [(poly, seg, points, 0.4, True)],
        "resolve_partial": [(seg, taken, seg + 0.01, taken, poly, math.radians(5.0), 0.4, True, 0.4, False)],
        "update_surfaces": [_update_sample(seg)],
        "place_segments": [(seg, 0.5, -0.2, math.cos(0.3), math.sin(0.3))],
        "landmark_rows": [(seg, kinds, 0.4)],
        "refine_pose": [
            (starts, seg, seg + 0.01, ok, points, seg, 0.0, 0.0, 0.0, 0.0, 0.0, 0.05, 0.1, 0.05, 2.0, 0.5, 8)
        ],
        "scan_points": [
            (scan_ranges, _readonly(scan_angles), 30.0, 2),
            (_readonly(scan_ranges), _readonly(scan_angles), 30.0, 2),
        ],
        "detect_exits": [(seg, kinds, 0.6, 1.2, 0.5, 6.0, True)],
        "seen_through": [(seg, ids, np.ones(2, dtype=np.bool_), 0.5, 0.0, poly)],
        "near_exit": [(seg, ids, ids, 1, 10, 1, 0.5, 0.0, 0.5)],
        "update_sides": [
            (seg, np.zeros(2, dtype=np.int64), np.zeros((2, 2)), np.zeros(2, dtype=np.int64), ids, ids)
            + (0.5, 0.0, 0.2, 1, 10, 1)
        ],
        "merge_collinear": [(seg, 0.1, 0.2, 0.4)],
        "colocated": [(seg, points.reshape(2, 4).copy(), ids, ids[:0], poly, seg, 0.4, True)],
        "same_any": [(seg, seg, 0.1, 0.4)],
        "match_structure": [
            (seg, np.array([-1, 1], dtype=np.int64), seg, 0.1, 0.4, 5, 1, poly, np.array([0, 3], dtype=np.int64))
            + (0, np.zeros(3), np.zeros(2), 0.8, 3.0)
        ],
    }


def sample_calls(*kernel_sets: object) -> Iterator[tuple[str, Callable[..., Any], tuple[Any, ...]]]:
    """``(kernel name, kernel, arguments)`` for every sample of every kernel of ``kernel_sets``."""
    samples = _samples()
    for kernels in kernel_sets:
        for name in kernel_names(kernels):
            for args in samples[name]:
                yield name, getattr(kernels, name), args


def warm_up(kernel_sets: tuple[object, ...], announce: Callable[[str], None] | None = None) -> None:
    """Call every kernel of ``kernel_sets`` once with its mappers' argument types: numba compiles them now.

    With numba's cache filled (any earlier run of this code version on this
    machine) this is a cache load. ``announce`` receives a line before and
    after a real compilation, none for a cache load.
    """
    cold = not compiled.is_cached()
    if cold and announce is not None:
        announce(f"albot1: compiling the numba kernels once for this code version (cache: {compiled.CACHE_DIR})")
    start = time.perf_counter()
    for _, kernel, args in sample_calls(*kernel_sets):
        kernel(*args)
    if cold and announce is not None:
        announce(f"albot1: kernels compiled in {time.perf_counter() - start:.1f} s")
