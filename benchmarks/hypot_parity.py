"""``python_hypot`` compiled against this interpreter's ``math.hypot``, bit for bit, on many random inputs.

Albot1+'s compiled localisation (``mapping/localise_kernels.py``) measures
with ``python_hypot``, CPython 3.11's two-argument ``math.hypot`` written out,
so that it ranks candidates with the same bits as the thesis's ``localise``.
The unit tests check edge cases, triples and a property test; this script
checks millions of inputs of the magnitudes a map holds and of the whole
float range (run it again on a new CPython: a changed ``math.hypot`` shows up
as mismatches)::

    PYTHONPATH=. python benchmarks/hypot_parity.py --count 10000000

Prints, per input family, the count and the mismatches of ``python_hypot``
and, for comparison, of numba's ``math.hypot`` (C's ``hypot``).
"""

from __future__ import annotations

import argparse
import math
import sys

import numba
import numpy as np
from numpy.typing import NDArray

from albot1.methods.albot1.mapping import localise_kernels


@numba.njit
def _ours(xs: NDArray[np.float64], ys: NDArray[np.float64]) -> NDArray[np.float64]:
    out = np.empty(xs.shape[0])
    for i in range(xs.shape[0]):
        out[i] = localise_kernels.python_hypot(xs[i], ys[i])
    return out


@numba.njit
def _c(xs: NDArray[np.float64], ys: NDArray[np.float64]) -> NDArray[np.float64]:
    out = np.empty(xs.shape[0])
    for i in range(xs.shape[0]):
        out[i] = math.hypot(xs[i], ys[i])
    return out


def _family(rng: np.random.Generator, name: str, n: int) -> NDArray[np.float64]:
    """``n`` inputs: landmark-sized (mm to tens of m, either sign), any finite bit pattern, or subnormal to tiny."""
    if name == "landmark":
        return rng.uniform(-20.0, 20.0, n) * 10.0 ** rng.uniform(-3.0, 0.5, n)
    if name == "any bits":
        v = rng.integers(0, 2**64, n, dtype=np.uint64).view(np.float64)
        return np.where(np.isfinite(v), v, 1.0)
    return rng.uniform(-1.0, 1.0, n) * 2.0 ** rng.uniform(-1074.0, -1000.0, n)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=10_000_000, help="inputs of the landmark family")
    parser.add_argument("--seed", type=int, default=24)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    sizes = {"landmark": args.count, "any bits": args.count // 10, "tiny": args.count // 10}
    bad = 0
    for name, size in sizes.items():
        xs, ys = _family(rng, name, size), _family(rng, name, size)
        expected = np.fromiter(map(math.hypot, xs.tolist(), ys.tolist()), dtype=float, count=size)
        ours = np.count_nonzero(_ours(xs, ys).view(np.int64) != expected.view(np.int64))
        c = np.count_nonzero(_c(xs, ys).view(np.int64) != expected.view(np.int64))
        bad += ours
        sys.stdout.write(f"{name:9s} {size:>10d} inputs: python_hypot {ours} mismatches, C hypot {c}\n")
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
