"""Fingerprints of every method's output on three datasets: the check that a refactor changed no result.

A refactor of method code (moving kernels, splitting a mapper, changing how
kernels are compiled) must leave every pose and every map bit for bit as it
was. This script runs each registered method that is available on this
machine (every Albot1 preset, the places mapper, the baselines) on three
datasets and prints one line per run with a sha256 of the poses, of the map
(segments and points, float64 bytes) and of the counters (less the
ones that measure time or memory), so two checkouts
can be compared line by line::

    python benchmarks/fingerprints.py > before.txt      # on the old code
    python benchmarks/fingerprints.py > after.txt       # on the new code
    diff before.txt after.txt                           # empty: bit-identical

The public logs are used when ``ALBOT1_DATA_DIR`` holds them (a prefix of each,
to keep the run to a few minutes); a missing log is reported as skipped, with
its reason, not silently left out.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from collections.abc import Iterator

import numpy as np

from albot1.data import open_sequence
from albot1.errors import Albot1Error
from albot1.methods.registry import method_registry
from albot1.runs.execute import run_method

#: Counters that are measurements of this machine (MRPT's wall time, peak memory), not outputs of the method.
MEASURED_SUFFIXES = ("_s", "_mb")

#: Three datasets: exact synthetic geometry, and prefixes of two public raw logs with their own odometry.
DATASETS = ("synthetic-office-loop", "aces[:400]", "mit-csail[:400]")


def _digest(array: object) -> str:
    if array is None:
        return "none"
    data = np.ascontiguousarray(np.asarray(array, dtype=np.float64))
    return hashlib.sha256(data.tobytes() + str(data.shape).encode()).hexdigest()[:16]


def runs() -> Iterator[tuple[str, str]]:
    """(method, preset) pairs: every Albot1 preset, the default of every other method."""
    for spec in method_registry():
        name = spec.name
        presets = sorted(spec.load_class().presets) if name == "albot1" else ["default"]
        for preset in presets:
            yield name, preset


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", nargs="*", default=list(DATASETS))
    parser.add_argument("--methods", nargs="*", default=None, help="method names (default: all available)")
    args = parser.parse_args(argv)
    for dataset in args.datasets:
        try:
            sequence = open_sequence(dataset)
        except Albot1Error as error:
            sys.stdout.write(f"{dataset}: skipped ({error})\n")
            continue
        for method, preset in runs():
            if args.methods and method not in args.methods:
                continue
            spec = method_registry().get(method)
            if not spec.available():
                sys.stdout.write(f"{dataset} {method}:{preset}: skipped ({spec.unavailable_reason()})\n")
                continue
            try:
                result = run_method(method, sequence, preset=preset, seed=0, dataset_name=dataset)
            except Albot1Error as error:
                sys.stdout.write(f"{dataset} {method}:{preset}: failed ({type(error).__name__}: {error})\n")
                continue
            counted = {k: v for k, v in result.counters.items() if not k.endswith(MEASURED_SUFFIXES)}
            counters = hashlib.sha256(json.dumps(counted, sort_keys=True).encode()).hexdigest()[:16]
            sys.stdout.write(
                f"{dataset} {method}:{preset} poses={_digest(result.poses)} "
                f"segments={_digest(result.map.segments)} points={_digest(result.map.points)} counters={counters}\n"
            )
            sys.stdout.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
