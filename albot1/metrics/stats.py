"""Summary statistics shared by every error metric.

One function so every block of ``metrics.json`` uses the same names and the
same conventions. ``std`` follows the tool each metric is checked against:
the relation metric uses the *sample* standard deviation (ddof = 1), because
the published ACES odometry numbers (2.675 m) are reproduced only with it;
ATE and RPE use the population one (ddof = 0), as evo does, so our numbers
and evo's agree digit for digit. The block says which (``std_ddof``).
``rmse`` is the root of the mean squared error.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike


def summarize(values: ArrayLike, *, ddof: int = 1) -> dict[str, Any]:
    """``mean, std, median, min, max, rmse, n, std_ddof`` of a 1-D sample (NaNs when empty)."""
    v = np.asarray(values, dtype=float).ravel()
    n = int(v.size)
    if n == 0:
        nan = float("nan")
        return {"mean": nan, "std": nan, "median": nan, "min": nan, "max": nan, "rmse": nan, "n": 0, "std_ddof": ddof}
    return {
        "mean": float(np.mean(v)),
        "std": float(np.std(v, ddof=ddof)) if n > ddof else float("nan"),
        "median": float(np.median(v)),
        "min": float(np.min(v)),
        "max": float(np.max(v)),
        "rmse": float(np.sqrt(np.mean(v * v))),
        "n": n,
        "std_ddof": ddof,
    }


def suffixed(summary: dict[str, Any], unit: str) -> dict[str, Any]:
    """The same summary with the unit in every value's key (``rmse`` -> ``rmse_m``); counts keep their names."""
    return {(key if key in ("n", "std_ddof") else f"{key}_{unit}"): value for key, value in summary.items()}
