"""The places kernels to run: jitted with numba or as written, in one typed set (same results either way)."""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from albot1.methods.albot1.jit import kernel_compiler
from albot1.methods.albot1.places import kernels
from albot1.methods.albot1.places.kernels import BoolArray, FloatArray, IntArray


class PlacesKernels(NamedTuple):
    """One consistent set of places kernels (all jitted or none); see :mod:`.kernels` for each."""

    jitted: bool
    merge_collinear: Callable[[FloatArray, float, float, float], FloatArray]
    seen_through: Callable[[FloatArray, IntArray, BoolArray, float, float, FloatArray], IntArray]
    same_any: Callable[[FloatArray, FloatArray, float, float], tuple[BoolArray, BoolArray]]
    near_exit: Callable[[FloatArray, IntArray, IntArray, int, int, int, float, float, float], bool]
    colocated: Callable[[FloatArray, FloatArray, IntArray, IntArray, FloatArray, FloatArray, float, bool], IntArray]
    update_sides: Callable[
        [FloatArray, IntArray, FloatArray, IntArray, IntArray, IntArray, float, float, float, int, int, int],
        tuple[IntArray, FloatArray, FloatArray],
    ]
    detect_exits: Callable[[FloatArray, IntArray, float, float, float, float, bool], tuple[IntArray, IntArray]]
    match_structure: Callable[
        [
            FloatArray,
            IntArray,
            FloatArray,
            float,
            float,
            int,
            int,
            FloatArray,
            IntArray,
            int,
            FloatArray,
            FloatArray,
            float,
            float,
        ],
        tuple[bool, int, float, float, float],
    ]


@lru_cache(maxsize=2)
def places_kernels(accelerate: bool = True) -> PlacesKernels:
    """The jitted kernels when ``accelerate`` and numba is importable, else the plain ones."""
    jit = kernel_compiler(
        accelerate,
        (
            kernels.merge_collinear,
            kernels.seen_through,
            kernels.same_any,
            kernels.near_exit,
            kernels.colocated,
            kernels.update_sides,
            kernels.detect_exits,
            kernels.match_structure,
        ),
    )
    compiled = PlacesKernels(
        jit.jitted,
        jit(kernels.merge_collinear),
        jit(kernels.seen_through),
        jit(kernels.same_any),
        jit(kernels.near_exit),
        jit(kernels.colocated),
        jit(kernels.update_sides),
        jit(kernels.detect_exits),
        jit(kernels.match_structure),
    )
    if compiled.jitted:
        _warm(compiled)
    return compiled


def _warm(k: PlacesKernels) -> None:
    """Call every kernel once on tiny inputs, so numba compiles them (or loads its cache) now, not mid-run.

    Most places kernels are first needed long after the first scan (the
    first exit crossed, the first match); without this their compilation
    would land on one scan's timing.
    """
    seg = np.array([[0.0, 1.0, 1.0, 1.0], [1.5, 1.0, 2.5, 1.0]])
    ids = np.arange(2, dtype=np.int64)
    poly = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [0.0, 3.0]])
    k.merge_collinear(seg, 0.1, 0.2, 0.4)
    k.seen_through(seg, ids, np.ones(2, dtype=np.bool_), 0.5, 0.0, poly)
    k.same_any(seg, seg, 0.1, 0.4)
    k.near_exit(seg, ids, ids, 1, 10, 1, 0.5, 0.0, 0.5)
    k.colocated(seg, np.column_stack([seg[:, :2], seg[:, 2:]]), ids, ids[:0], poly, seg, 0.4, True)
    k.update_sides(
        seg,
        np.zeros(2, dtype=np.int64),
        np.zeros((2, 2)),
        np.zeros(2, dtype=np.int64),
        ids,
        ids,
        0.5,
        0.0,
        0.2,
        1,
        10,
        1,
    )
    k.detect_exits(seg, np.ones((2, 2), dtype=np.int64), 0.6, 1.2, 0.5, 6.0, True)
    k.match_structure(
        seg,
        np.array([-1, 1], dtype=np.int64),
        seg,
        0.1,
        0.4,
        5,
        1,
        poly,
        np.array([0, 4], dtype=np.int64),
        0,
        np.zeros(3),
        np.zeros(2),
        0.8,
        3.0,
    )
