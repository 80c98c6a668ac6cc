"""Cost: per-scan time, total time, peak memory, and whether cost grows with the work.

Per-scan time is what the runner measured around ``process`` alone
(``per_scan_ns.npy``). Growth is shown by the median per-scan time in each
tenth of the sequence and by the least-squares slope of those medians
against the position (ms per 1000 scans): a method whose map grows without
bound shows a rising slope, a constant-time method a flat one. The start-up
(``startup_s``: compiling or loading compiled kernels before the first scan)
is carried apart, never in a per-scan figure. Medians per
decile rather than raw times make the slope robust to the odd scan stalled
by the operating system.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from albot1.metrics.errors import MetricsError

DECILES = 10


def cost(per_scan_ns: ArrayLike, timing: dict[str, Any] | None = None, *, bins: int = DECILES) -> dict[str, Any]:
    """The ``cost`` block (ms, s, MiB) from per-scan times and the run's timing block."""
    ns = np.asarray(per_scan_ns, dtype=float).ravel()
    if len(ns) == 0:
        raise MetricsError("cost: the run has no per-scan times")
    if np.any(ns < 0) or not np.isfinite(ns).all():
        raise MetricsError(
            f"cost: per-scan times must be finite and non-negative (first bad at scan "
            f"{int(np.flatnonzero(~(np.isfinite(ns) & (ns >= 0)))[0])})"
        )
    ms = ns / 1e6
    timing = timing or {}
    edges = np.linspace(0, len(ms), min(bins, len(ms)) + 1).astype(int)
    centres, medians = [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        if hi > lo:
            centres.append((lo + hi - 1) / 2.0)
            medians.append(float(np.median(ms[lo:hi])))
    slope = float(np.polyfit(centres, medians, 1)[0]) * 1000.0 if len(centres) > 1 else None
    return {
        "units": {"per_scan": "ms", "total": "s", "peak": "MiB", "slope": "ms per 1000 scans"},
        "scans": int(len(ms)),
        "per_scan_ms_median": float(np.median(ms)),
        "per_scan_ms_p95": float(np.percentile(ms, 95)),
        "per_scan_ms_mean": float(np.mean(ms)),
        "per_scan_ms_max": float(np.max(ms)),
        "process_total_s": float(ns.sum() / 1e9),
        "total_s": timing.get("total_s"),
        "finish_s": timing.get("finish_s"),
        "startup_s": timing.get("startup_s"),
        "peak_mb": timing.get("peak_mb"),
        "by_position": {"scan_centres": centres, "per_scan_ms_median": medians},
        "growth_slope_ms_per_1000_scans": slope,
        "last_over_first_decile": (medians[-1] / medians[0]) if len(medians) > 1 and medians[0] > 0 else None,
    }
