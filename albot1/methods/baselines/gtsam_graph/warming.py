"""One warm-up for gtsam-graph's compiled kernels: the wheel's bundle first, then numba's cache, else a compile.

Why one implementation: the grid search (:mod:`.nearest`), the block sums
(:mod:`.block_sums`) and the ICP loop (:mod:`.icp_loop`) each warm their
kernels before a run's first scan, with the run's argument types, so that no
compile lands in a timed scan (issue 24), and each says so on the terminal
only when it really compiles (none for a cache load). The steps are the same
for all three; only the kernels, their sample calls and the name differ.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from albot1.methods.albot1 import compiled, kernel_bundle

SampleCalls = Callable[[], Iterable[tuple[str, Callable[..., Any], tuple[Any, ...]]]]


def warm_kernels(
    kernels: Sequence[Callable[..., Any]],
    sample_calls: SampleCalls,
    what: str,
    announce: Callable[[str], None] | None,
    run: Callable[[], object] | None = None,
) -> None:
    """Load ``kernels`` from the wheel's bundle or numba's cache, or compile them, saying so when it compiles.

    ``sample_calls``: the ``(name, kernel, arguments)`` the bundle was built from (the run's argument types);
    ``run``: what makes the kernels compile as a run calls them (default: each sample call).
    """
    if any(compiled.needs_compile(k) for k in kernels):
        kernel_bundle.seed(sample_calls(), compiled.needs_compile)
    cold = any(compiled.needs_compile(k) for k in kernels)
    if cold and announce is not None:
        announce(f"gtsam-graph: compiling its {what} once for this code version (cache: {compiled.CACHE_DIR})")
    start = time.perf_counter()
    if run is not None:
        run()
    else:
        for _, fn, args in sample_calls():
            fn(*args)
    if cold and announce is not None:
        announce(f"gtsam-graph: {what} compiled in {time.perf_counter() - start:.1f} s")
