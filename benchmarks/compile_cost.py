"""What a cold numba compile of Albot1's kernels costs, per kernel or as the warm-up runs it (issue 24).

Each invocation is one fresh process on an empty kernel cache (``XDG_CACHE_HOME``
pointed at a new temporary folder before albot1 is imported, so
``compiled.CACHE_DIR`` is empty), and reports CPU seconds, which a loaded
machine inflates less than wall time::

    python benchmarks/compile_cost.py kernels places     # each kernel's sample in turn, one process
    python benchmarks/compile_cost.py warm-up plus       # warm_up as a run calls it, helpers included
    python benchmarks/compile_cost.py warm-up bench [--one-by-one]   # every kernel, as the bench's forkserver

``kernels``: the CPU of each kernel's first call (a callee shared with an
earlier kernel is charged to the earlier one). ``warm-up``: wall time, this
process's CPU and its helper processes' CPU (``ALBOT1_COMPILE_PROCESSES``
applies), and the *critical path*: per warm-up, the larger of this process's
CPU and its helpers' (a helper runs beside this process, which waits for it
at the end of each warm-up), summed: what an idle machine with a core per
process would wait, an estimate that a loaded machine inflates much less
than the wall time. The kernel sets are those the presets' warm-ups compile:
``thesis`` (every preset but ``plus``), ``plus`` (also Albot1+'s pose
kernels), ``places`` (``albot1-places`` default: the thesis kernels and
the places layer's) and ``bench`` (every kernel, as the forkserver warms
every preset of both methods: one warm-up inside ``warm_up.together()``, or
with ``--one-by-one`` three warm-ups in the order the presets add kernels,
thesis, ``plus``, places, as the preload made them before). See
``docs/albot1-mapper.md``, "Compile time".
"""

from __future__ import annotations

import argparse
import contextlib
import os
import resource
import tempfile
import time
from typing import Any


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=["kernels", "warm-up"])
    parser.add_argument("preset", choices=["thesis", "plus", "places", "bench"])
    parser.add_argument("--one-by-one", action="store_true", help="bench: one warm-up per kernel set, not together")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="albot1-compile-cost-") as cache:
        os.environ["XDG_CACHE_HOME"] = cache  # read when albot1's compiled module picks its cache folder
        start = time.process_time()
        from albot1.methods.albot1.mapping.kernel_set import MappingKernels
        from albot1.methods.albot1.perception.kernels import PerceptionKernels
        from albot1.methods.albot1.places.kernels import PlacesKernels
        from albot1.methods.albot1.warm_up import sample_calls, together, warm_up

        thesis_skip = MappingKernels.not_called("")
        plus_skip = MappingKernels.not_called("robust")  # the kernels plus's fused ones compile into themselves
        base: tuple[object, ...] = (PerceptionKernels(), MappingKernels())
        # (kernel sets, skip) of each warm-up, in turn, as the mappers' warm-ups skip them
        every: dict[str, list[tuple[tuple[object, ...], tuple[str, ...]]]] = {
            "thesis": [(base, thesis_skip)],
            "plus": [(base, plus_skip)],
            "places": [((*base, PlacesKernels()), thesis_skip)],
            "bench": [(base, thesis_skip), (base, plus_skip), ((*base, PlacesKernels()), ())],
        }
        warm_ups = every[args.preset]
        imported = time.process_time() - start
        if args.mode == "warm-up":
            joined = args.preset == "bench" and not args.one_by_one
            forked = _timing_forks()
            wall = time.perf_counter()
            own_start, helpers_start = time.process_time(), _children_cpu()
            critical = 0.0
            with together() if joined else contextlib.nullcontext():
                for kernel_sets, skip in warm_ups:  # (inside together() these only note their kernels)
                    own, helper = _warm_up_cpu(warm_up, kernel_sets, skip, forked)
                    critical += max(own, helper)
            own_total, helper_total = time.process_time() - own_start, _children_cpu() - helpers_start
            if joined:
                critical = max(own_total, forked[0] - own_start + helper_total if forked else 0.0)
            how = " one by one" if args.one_by_one else ""
            print(
                f"{args.preset}{how} warm-up: wall {time.perf_counter() - wall:.2f} s, CPU this process "
                f"{own_total:.2f} s, helpers {helper_total:.2f} s, critical path {critical:.2f} s"
            )
            return 0
        kernel_sets, skip = warm_ups[-1]
        calls = [call for call in sample_calls(*kernel_sets) if call[0] not in skip]
        per_kernel: dict[str, float] = {}
        for name, kernel, sample in calls:
            cpu = time.process_time()
            kernel(*sample)
            per_kernel[name] = per_kernel.get(name, 0.0) + time.process_time() - cpu
        rows = " ".join(f"{name}={seconds:.2f}" for name, seconds in per_kernel.items())
        print(f"{args.preset} kernels: import {imported:.2f} s, compile {sum(per_kernel.values()):.2f} s CPU | {rows}")
    return 0


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _timing_forks() -> list[float]:
    """This process's CPU clock each time a warm-up starts its helpers (a helper's CPU counts from there)."""
    from albot1.methods.albot1 import warm_up

    forked: list[float] = []
    start_helpers = warm_up._helpers

    def timed(*args: Any) -> Any:
        forked.append(time.process_time())
        return start_helpers(*args)

    warm_up._helpers = timed  # type: ignore[assignment]  # a measurement script, not library code
    return forked


def _warm_up_cpu(
    warm_up: Any, kernel_sets: tuple[object, ...], skip: tuple[str, ...], forked: list[float]
) -> tuple[float, float]:
    """One ``warm_up`` call's CPU: this process's, and the helpers' counted from this process's clock at the fork.

    The second is what an idle machine waits for the helpers (they start
    when this process has compiled the first kernel and join at the end).
    """
    own, helpers, forks = time.process_time(), _children_cpu(), len(forked)
    warm_up(kernel_sets, skip=skip)
    helper = _children_cpu() - helpers
    return time.process_time() - own, (forked[forks] - own + helper) if len(forked) > forks else 0.0


if __name__ == "__main__":
    raise SystemExit(main())
