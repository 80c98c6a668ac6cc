"""One round of issue 24's cost comparison: KISS-ICP, Albot1 ``thesis`` and ``plus`` on the full Intel log.

The same measurement as ``test_bench_albot1.py -k beside`` (its
``_per_scan_ns``: per-scan CPU time of the calling thread, after a warm-up),
as one JSON line per call, so that rounds of old and new code can alternate
in fresh processes (``PYTHONPATH`` names the checkout measured)::

    for r in 1 2 3; do for tree in ../old-checkout .; do
        PYTHONPATH=$tree python benchmarks/beside_rounds.py
    done; done

Only ratios within one round mean anything on a shared machine. ``--lockstep``
runs the three mappers side by side instead: every scan goes to each of them
in turn (the order rotating from scan to scan), so a slower or faster stretch
of the machine falls on all three alike. Its ratios are steadier (thesis /
KISS-ICP 0.245-0.249 in three rounds of one code, where the default mode gave
0.15-0.20) but higher: each mapper finds the caches filled by the other two,
which costs the cheap per-scan step relatively more. So it compares two
versions of the same method well (both pay alike), and is not the measure of
issue 24's ratios, which is the default mode (docs/albot1-mapper.md, "The
thesis presets' localisation compiled too"). The runs take
the environment's config overrides (``ALBOT1_ALBOT1_KEPT_VIEWS_TEACH=false``
measures ``plus`` without that field), and each line lists the ones set.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_bench_albot1 import _per_scan_ns  # noqa: E402

import albot1  # noqa: E402
from albot1.data.loaders.registry import load  # noqa: E402
from albot1.data.synthetic.worlds import load_world  # noqa: E402
from albot1.data.transforms import head  # noqa: E402
from albot1.methods.albot1.mapping.mapper import Albot1Mapper  # noqa: E402
from albot1.methods.baselines.kiss_icp import KissIcpMapper  # noqa: E402
from albot1.methods.registry import resolve_config  # noqa: E402

#: Environment variables that override a measured run's config (``albot1.config.env``).
OVERRIDE_PREFIXES = ("ALBOT1_ALBOT1_", "ALBOT1_KISS_ICP_")

RUNS = (("kiss", "kiss-icp", "default"), ("thesis", "albot1", "thesis"), ("plus", "albot1", "plus"))


def _lockstep_ns(frames: list[Any]) -> dict[str, np.ndarray]:
    """Per-scan CPU time (ns, this thread) of each run of :data:`RUNS`, the scans fed to all of them in turn."""
    mappers = {
        name: (
            Albot1Mapper(resolve_config("albot1", preset))  # type: ignore[arg-type]
            if method == "albot1"
            else KissIcpMapper(resolve_config("kiss-icp", preset))  # type: ignore[arg-type]
        )
        for name, method, preset in RUNS
    }
    names = list(mappers)
    out = {name: np.empty(len(frames), dtype=np.int64) for name in names}
    for i, frame in enumerate(frames):
        for k in range(len(names)):
            name = names[(i + k) % len(names)]  # each method first, second and last in turn
            t0 = time.thread_time_ns()
            mappers[name].process(frame)
            out[name][i] = time.thread_time_ns() - t0
    for mapper in mappers.values():
        mapper.finish()
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lockstep", action="store_true", help="feed every scan to the three mappers in turn")
    args = parser.parse_args()
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
    out["mode"] = "lockstep" if args.lockstep else "one after the other"
    means: dict[str, float] = {}
    lockstep = _lockstep_ns(frames) if args.lockstep else {}
    for name, method, preset in RUNS:
        ms = (lockstep[name] if args.lockstep else _per_scan_ns(frames, preset, time.thread_time_ns, method)) / 1e6
        means[name] = float(ms.mean())
        out[name] = {"mean_ms": means[name], "median_ms": float(np.median(ms))}
    out["thesis_over_kiss"] = means["thesis"] / means["kiss"]
    out["plus_over_kiss"] = means["plus"] / means["kiss"]
    sys.stdout.write(json.dumps(out) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
