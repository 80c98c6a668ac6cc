"""Orientation error: the thesis's Experiment 2 (Table 3.1) on any log.

At each stop point the robot "points home": the bearing of the start
position relative to its current heading (degrees, + = turn left, as the
thesis signs it) and the distance to it (m), once as the method's estimate
says and once as the reference says. The difference is how well the
method's map lets the robot orient itself. Both quantities are expressed in
the robot's own frame relative to its own start, so no alignment is needed.

Stop points are every ``every_m`` metres of *reference* travel (the same
scans for every method on a dataset) plus the final scan. A bearing is
undefined at the start itself, so rows whose reference distance to the start
is below ``min_distance_m`` keep their distances but leave the bearing error
out (``null``), and the block counts them. So do rows where the *estimate*
puts the robot on its own start (within :data:`AT_START_M`, e.g. a run that
never moved): its bearing home would be ``atan2(0, 0)``, a direction made up
by the arithmetic (it used to score a standing run 180 deg off on a straight
route); ``estimate_bearing_deg`` is null there and the distance error stays.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from albot1.geometry import se2
from albot1.metrics.alignment import check_pair
from albot1.metrics.errors import MetricsError

EVERY_M = 10.0
MIN_DISTANCE_M = 1.0
#: An estimate closer than this to its own start has no direction home (float round-off, not a bearing).
AT_START_M = 1e-6


def stop_indices(reference: ArrayLike, every_m: float = EVERY_M) -> NDArray[np.int64]:
    """First scan at or past each multiple of ``every_m`` of reference travel, and the last scan."""
    if every_m <= 0:
        raise MetricsError(f"orientation: expected a positive stop spacing, got {every_m} m")
    ref = np.asarray(reference, dtype=float)
    travel = se2.cumulative_length(ref)
    marks = np.arange(every_m, travel[-1] + 1e-12, every_m)
    stops = np.searchsorted(travel, marks - 1e-9, side="left")
    return np.unique(np.concatenate([stops, [len(ref) - 1]])).astype(np.int64)


def home_vector(poses: ArrayLike, index: int) -> tuple[float, float]:
    """``(bearing_deg, distance_m)`` of ``poses[0]`` seen from ``poses[index]``."""
    p = np.asarray(poses, dtype=float)
    local = se2.between(p[index], p[0])
    return float(np.degrees(np.arctan2(local[1], local[0]))), float(np.hypot(local[0], local[1]))


def orientation_table(
    estimate: ArrayLike,
    reference: ArrayLike,
    timestamps: ArrayLike | None = None,
    *,
    every_m: float = EVERY_M,
    min_distance_m: float = MIN_DISTANCE_M,
) -> dict[str, Any]:
    """The ``orientation`` block: Table-3.1 rows and mean/max absolute differences."""
    est, ref = check_pair(estimate, reference, "orientation")
    stamps = None if timestamps is None else np.asarray(timestamps, dtype=float)
    travel = se2.cumulative_length(ref)
    rows: list[dict[str, Any]] = []
    bearing_err: list[float] = []
    distance_err: list[float] = []
    for k in stop_indices(ref, every_m):
        if k == 0:
            continue
        b_est, d_est = home_vector(est, int(k))
        b_ref, d_ref = home_vector(ref, int(k))
        at_start = d_est < AT_START_M  # the estimate says the robot is home: no bearing to point
        defined = d_ref >= min_distance_m and not at_start
        b_diff = float(np.degrees(se2.wrap(np.radians(b_est - b_ref)))) if defined else None
        rows.append(
            {
                "scan": int(k),
                "timestamp": float(stamps[k]) if stamps is not None else None,
                "travel_m": float(travel[k]),
                "estimate_bearing_deg": None if at_start else b_est,
                "estimate_distance_m": d_est,
                "reference_bearing_deg": b_ref,
                "reference_distance_m": d_ref,
                "bearing_error_deg": b_diff,
                "distance_error_m": d_est - d_ref,
            }
        )
        if b_diff is not None:
            bearing_err.append(abs(b_diff))
        distance_err.append(abs(d_est - d_ref))

    def mean_max(values: list[float]) -> tuple[float | None, float | None]:
        return (float(np.mean(values)), float(np.max(values))) if values else (None, None)

    b_mean, b_max = mean_max(bearing_err)
    d_mean, d_max = mean_max(distance_err)
    return {
        "alignment": "none (bearing and distance are relative to the robot's own start)",
        "units": {"bearing": "deg, + = start is to the left", "distance": "m"},
        "every_m": every_m,
        "min_distance_m": min_distance_m,
        "stops": len(rows),
        "bearing_undefined": len(rows) - len(bearing_err),
        "bearing_abs_error_mean_deg": b_mean,
        "bearing_abs_error_max_deg": b_max,
        "distance_abs_error_mean_m": d_mean,
        "distance_abs_error_max_m": d_max,
        "rows": rows,
    }
