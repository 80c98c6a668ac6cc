"""Every float32 that albot1.runs.float32_text writes itself, against numpy's own text (session 26, issue 24).

``map.geojson`` keeps its bytes only if :func:`albot1.runs.float32_text.float32_fields` writes each value of
its range (zero and 1e-4 < |x| < 1e6) as numpy's Dragon4 does. The unit tests check boundaries and samples;
this checks all of them, one sign per run (~285 million values, ~15-20 min of one core on the 2-core machine)::

    python benchmarks/float32_text_exhaustive.py --sign 0
    python benchmarks/float32_text_exhaustive.py --sign 1

Each chunk of consecutive bit patterns is written by ``float32_fields`` and by numpy (``astype(StringDType())``,
the general path of ``map_files.numpy_texts``), one value per line, and the two texts compared; a differing
chunk prints its first differing value. Exit status 1 when any chunk differs.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from numpy.dtypes import StringDType

from albot1.runs.float32_text import HIGH, LOW, float32_fields
from albot1.runs.map_files import numpy_texts

CHUNK = 1 << 21


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sign", type=int, choices=(0, 1), required=True, help="0: positive values, 1: negative")
    args = parser.parse_args(argv)
    first = int(np.array(LOW, dtype=np.float32).view(np.uint32)) + 1  # the range is open at both ends
    last = int(np.array(HIGH, dtype=np.float32).view(np.uint32)) - 1
    sign = np.uint32(args.sign << 31)
    started, checked, differing = time.perf_counter(), 0, 0
    for start in range(first, last + 1, CHUNK):
        bits = np.arange(start, min(start + CHUNK, last + 1), dtype=np.int64).astype(np.uint32) | sign
        values = np.concatenate([bits.view(np.float32), np.array([0.0, -0.0], dtype=np.float32)])
        fields = float32_fields(values, numpy_texts)
        lines = np.concatenate([fields, np.full((len(fields), 1), ord("\n"), dtype=np.uint8)], axis=1)
        written = lines[lines != 0].tobytes().decode("ascii").split("\n")[:-1]
        expected = values.astype(StringDType()).tolist()
        checked += len(values)
        if written != expected:
            differing += 1
            at = next(i for i, (w, e) in enumerate(zip(written, expected, strict=True)) if w != e)
            print(f"DIFFERS: {values[at]!r} written {written[at]!r}, numpy {expected[at]!r}", flush=True)
        if (start - first) // CHUNK % 25 == 0:
            print(
                f"at {values[0]!r}: {checked:,} values, {differing} differing chunks, "
                f"{time.perf_counter() - started:.0f} s",
                flush=True,
            )
    print(f"sign {args.sign}: {checked:,} values checked, {differing} differing chunks", flush=True)
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())
