"""What a cold numba compile of Albot1's kernels costs, per kernel or as the warm-up runs it (issue 24).

Each invocation is one fresh process on an empty kernel cache (``XDG_CACHE_HOME``
pointed at a new temporary folder before albot1 is imported, so
``compiled.CACHE_DIR`` is empty), and reports CPU seconds, which a loaded
machine inflates less than wall time::

    python benchmarks/compile_cost.py kernels places     # each kernel's sample in turn, one process
    python benchmarks/compile_cost.py warm-up plus       # warm_up as a run calls it, helpers included

``kernels``: the CPU of each kernel's first call (a callee shared with an
earlier kernel is charged to the earlier one). ``warm-up``: wall time, this
process's CPU and its helper processes' CPU (``ALBOT1_COMPILE_PROCESSES``
applies). The kernel sets are those the presets' warm-ups compile:
``thesis`` (every preset but ``plus``), ``plus`` (also Albot1+'s pose
kernels) and ``places`` (``albot1-places`` default: the thesis kernels and
the places layer's). See ``docs/albot1-mapper.md``, "Compile time".
"""

from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=["kernels", "warm-up"])
    parser.add_argument("preset", choices=["thesis", "plus", "places"])
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="albot1-compile-cost-") as cache:
        os.environ["XDG_CACHE_HOME"] = cache  # read when albot1's compiled module picks its cache folder
        start = time.process_time()
        from albot1.methods.albot1.mapping.kernel_set import MappingKernels
        from albot1.methods.albot1.perception.kernels import PerceptionKernels
        from albot1.methods.albot1.places.kernels import PlacesKernels
        from albot1.methods.albot1.warm_up import sample_calls, warm_up

        kernel_sets: tuple[object, ...] = (PerceptionKernels(), MappingKernels())
        if args.preset == "places":
            kernel_sets = (*kernel_sets, PlacesKernels())
        skip = MappingKernels.not_called("robust" if args.preset == "plus" else "")
        imported = time.process_time() - start
        if args.mode == "warm-up":
            wall = time.perf_counter()
            cpu = time.process_time()
            warm_up(kernel_sets, skip=skip)
            helpers = resource.getrusage(resource.RUSAGE_CHILDREN)
            print(
                f"{args.preset} warm-up: wall {time.perf_counter() - wall:.2f} s, CPU this process "
                f"{time.process_time() - cpu:.2f} s, helpers {helpers.ru_utime + helpers.ru_stime:.2f} s"
            )
            return 0
        calls = [call for call in sample_calls(*kernel_sets) if call[0] not in skip]
        per_kernel: dict[str, float] = {}
        for name, kernel, sample in calls:
            cpu = time.process_time()
            kernel(*sample)
            per_kernel[name] = per_kernel.get(name, 0.0) + time.process_time() - cpu
        rows = " ".join(f"{name}={seconds:.2f}" for name, seconds in per_kernel.items())
        print(f"{args.preset} kernels: import {imported:.2f} s, compile {sum(per_kernel.values()):.2f} s CPU | {rows}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
