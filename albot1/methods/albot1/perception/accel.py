"""The perception kernels to run: jitted with numba or as written, in one typed set.

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
from albot1.methods.albot1.perception import kernels
from albot1.methods.albot1.perception.kernels import FloatArray, IntArray


class PerceptionKernels(NamedTuple):
    """One consistent set of perception kernels (all jitted or none); see :mod:`.kernels` for each."""

    jitted: bool
    build_view: Callable[
        [FloatArray, FloatArray, float, float, float, float, float, float, float, float, float, float, bool],
        tuple[FloatArray, IntArray, IntArray, IntArray],
    ]
    recognise_landmarks: Callable[
        [FloatArray, IntArray, FloatArray, IntArray, float, float, float, float, float, bool],
        tuple[IntArray, IntArray, IntArray, FloatArray, FloatArray, FloatArray, FloatArray],
    ]


@lru_cache(maxsize=2)
def perception_kernels(accelerate: bool = True) -> PerceptionKernels:
    """The jitted kernels when ``accelerate`` and numba is importable, else the plain ones."""
    jit = kernel_compiler(accelerate, (kernels.build_view, kernels.recognise_landmarks))
    return PerceptionKernels(jit.jitted, jit(kernels.build_view), jit(kernels.recognise_landmarks))
