"""The map-update and Albot1+ pose kernels to run: jitted with numba or as written, in one typed set.

Acceleration never changes results: both variants run the same source
(:mod:`albot1.methods.albot1.jit`). A set is built once per process and flag;
when numba cannot be imported the interpreted kernels are used, which is slow
but exact.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import NamedTuple

from albot1.methods.albot1.jit import kernel_compiler
from albot1.methods.albot1.mapping import kernels, pose_kernels
from albot1.methods.albot1.mapping.kernels import BoolArray, FloatArray, IntArray


class MappingKernels(NamedTuple):
    """One consistent set of mapping kernels (all jitted or none); see :mod:`.kernels` for each."""

    jitted: bool
    classify_endpoints: Callable[[FloatArray, FloatArray, FloatArray, float, bool], BoolArray]
    best_correspondence: Callable[[FloatArray, FloatArray, BoolArray, float, float], int]
    clip_parameter: Callable[[FloatArray, FloatArray, float, float, float, float, float, bool], float]
    resolve_partial: Callable[
        [FloatArray, BoolArray, FloatArray, BoolArray, FloatArray, float, float, bool, float, bool],
        tuple[IntArray, FloatArray, IntArray],
    ]
    refine_pose: Callable[..., tuple[float, float, float, FloatArray]]
    scan_points: Callable[[FloatArray, FloatArray, float, int], FloatArray]


@lru_cache(maxsize=2)
def mapping_kernels(accelerate: bool = True) -> MappingKernels:
    """The jitted kernels when ``accelerate`` and numba is importable, else the plain ones."""
    jit = kernel_compiler(
        accelerate,
        (
            kernels.classify_endpoints,
            kernels.best_correspondence,
            kernels.clip_parameter,
            kernels.resolve_partial,
            pose_kernels.refine_pose,
            pose_kernels.scan_points,
        ),
    )
    return MappingKernels(
        jit.jitted,
        jit(kernels.classify_endpoints),
        jit(kernels.best_correspondence),
        jit(kernels.clip_parameter),
        jit(kernels.resolve_partial),
        jit(pose_kernels.refine_pose),
        jit(pose_kernels.scan_points),
    )
