"""One round of issue 24's cost comparison: KISS-ICP, Albot1 ``thesis`` and ``plus`` on the full Intel log.

The same measurement as ``test_bench_albot1.py -k beside`` (its
``_per_scan_ns``: per-scan CPU time of the calling thread, after a warm-up),
as one JSON line per call, so that rounds of old and new code can alternate
in fresh processes (``PYTHONPATH`` names the checkout measured)::

    for r in 1 2 3; do for tree in ../old-checkout .; do
        PYTHONPATH=$tree python benchmarks/beside_rounds.py
    done; done

Only ratios within one round mean anything on a shared machine. The runs take
the environment's config overrides (``ALBOT1_ALBOT1_KEPT_VIEWS_TEACH=false``
measures ``plus`` without that field), and each line lists the ones set.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_bench_albot1 import _per_scan_ns  # noqa: E402

import albot1  # noqa: E402
from albot1.data.loaders.registry import load  # noqa: E402
from albot1.data.synthetic.worlds import load_world  # noqa: E402
from albot1.data.transforms import head  # noqa: E402

#: Environment variables that override a measured run's config (``albot1.config.env``).
OVERRIDE_PREFIXES = ("ALBOT1_ALBOT1_", "ALBOT1_KISS_ICP_")

RUNS = (("kiss", "kiss-icp", "default"), ("thesis", "albot1", "thesis"), ("plus", "albot1", "plus"))


def main() -> int:
    data = os.environ.get("ALBOT1_DATA_DIR")
    if not data or not (Path(data) / "radish" / "intel.clf.bz2").is_file():
        sys.stderr.write("beside_rounds: ALBOT1_DATA_DIR must hold radish/intel.clf.bz2\n")
        return 2
    frames = list(load(Path(data) / "radish" / "intel.clf.bz2"))
    _per_scan_ns(list(head(load_world("synthetic-office-loop"), 30)))
    for _, method, preset in RUNS:  # compile / load every kernel before timing
        _per_scan_ns(frames[:50], preset, time.thread_time_ns, method)
    out: dict[str, object] = {"code": str(Path(albot1.__file__).resolve().parent.parent)}
    # The environment overrides the runs took (``ALBOT1_ALBOT1_*``, ``ALBOT1_KISS_ICP_*``): a round says what it ran.
    out["overrides"] = {k: v for k, v in sorted(os.environ.items()) if k.startswith(OVERRIDE_PREFIXES)}
    means: dict[str, float] = {}
    for name, method, preset in RUNS:
        ms = _per_scan_ns(frames, preset, time.thread_time_ns, method) / 1e6
        means[name] = float(ms.mean())
        out[name] = {"mean_ms": means[name], "median_ms": float(np.median(ms))}
    out["thesis_over_kiss"] = means["thesis"] / means["kiss"]
    out["plus_over_kiss"] = means["plus"] / means["kiss"]
    sys.stdout.write(json.dumps(out) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
