"""The places kernels to run: jitted with numba or as written, in one typed set (same results either way)."""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import NamedTuple

from albot1.methods.albot1.jit import kernel_compiler
from albot1.methods.albot1.places import kernels
from albot1.methods.albot1.places.kernels import BoolArray, FloatArray, IntArray


class PlacesKernels(NamedTuple):
    """One consistent set of places kernels (all jitted or none); see :mod:`.kernels` for each."""

    jitted: bool
    merge_collinear: Callable[[FloatArray, float, float, float], FloatArray]
    seen_through: Callable[[FloatArray, IntArray, BoolArray, float, float, FloatArray], IntArray]
    near_exit: Callable[[FloatArray, IntArray, IntArray, int, int, int, float, float, float], bool]
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
            kernels.near_exit,
            kernels.update_sides,
            kernels.detect_exits,
            kernels.match_structure,
        ),
    )
    return PlacesKernels(
        jit.jitted,
        jit(kernels.merge_collinear),
        jit(kernels.seen_through),
        jit(kernels.near_exit),
        jit(kernels.update_sides),
        jit(kernels.detect_exits),
        jit(kernels.match_structure),
    )
