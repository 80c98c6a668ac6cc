"""The kernels of :mod:`albot1.methods.albot1.perception.kernels`, jitted with numba or as written.

Acceleration never changes results: both variants run the same source. The
jitted set is built once per process (numba's on-disk cache makes later
processes start in well under a second); when numba cannot be imported the
interpreted kernels are used, which is slow but exact.
"""

from __future__ import annotations

import types
from functools import lru_cache
from typing import Any

from albot1.methods.albot1.perception import kernels

#: every kernel function; helpers are jitted too because jitted code can only call jitted code.
_NAMES = (
    "build_view",
    "_occlusion",
    "_corner",
    "wrap_angle",
    "recognise_landmarks",
    "classify_endpoints",
    "best_correspondence",
    "segment_distance",
    "_point_segment",
    "_segments_cross",
    "_orient",
    "clip_parameter",
    "segment_cells",
)


class Kernels:
    """Attribute access to one consistent set of kernels (all jitted or none)."""

    def __init__(self, functions: dict[str, Any], jitted: bool) -> None:
        self.jitted = jitted
        for name, fn in functions.items():
            setattr(self, name.lstrip("_"), fn)


@lru_cache(maxsize=2)
def get_kernels(accelerate: bool = True) -> Kernels:
    """The jitted kernels when ``accelerate`` and numba is importable, else the plain ones."""
    plain = {name: getattr(kernels, name) for name in _NAMES}
    if not accelerate:
        return Kernels(plain, jitted=False)
    try:
        import numba
    except ImportError:
        return Kernels(plain, jitted=False)
    # Clones share one globals dict in which every helper is replaced by its jitted
    # version, so jitted callers resolve jitted callees when they compile.
    shared = dict(vars(kernels))
    for name, fn in plain.items():
        clone = types.FunctionType(fn.__code__, shared, fn.__name__, fn.__defaults__, fn.__closure__)
        clone.__qualname__ = fn.__qualname__
        clone.__module__ = fn.__module__
        shared[name] = numba.njit(cache=True, nogil=True)(clone)
    return Kernels({name: shared[name] for name in _NAMES}, jitted=True)
