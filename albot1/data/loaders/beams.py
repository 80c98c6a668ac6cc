"""Beam geometry that more than one log format needs (kept out of any one format's package).

A format that can only describe evenly spaced beams (a ROS LaserScan, an
albot-log SENSOR line) asks :func:`even_spacing` whether a scan's angles are
``first + i * step``; formats never import each other (issue 20).
"""

from __future__ import annotations

import numpy as np

from albot1.geometry.types import FloatArray

__all__ = ["ANGLE_SPACING_TOLERANCE", "even_spacing"]

#: Beam angles that differ from ``angle_min + i * angle_increment`` by more
#: than this cannot be written as a LaserScan (which only knows even spacing).
ANGLE_SPACING_TOLERANCE = 1e-6


def even_spacing(angles: FloatArray, tolerance: float = ANGLE_SPACING_TOLERANCE) -> tuple[float, float] | None:
    """``(angle_min, angle_increment)`` if the beams are evenly spaced (within ``tolerance`` rad), else None."""
    n = angles.shape[0]
    if n == 0 or not np.isfinite(angles).all():
        return None
    first = float(angles[0])
    step = float(angles[-1] - angles[0]) / (n - 1) if n > 1 else 0.0
    rebuilt = first + np.arange(n, dtype=np.float64) * step
    with np.errstate(invalid="ignore", over="ignore"):
        if not float(np.max(np.abs(rebuilt - angles))) <= tolerance:
            return None
    return first, step
