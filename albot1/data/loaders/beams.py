"""Beam geometry that more than one log format needs (kept out of any one format's package).

A format that can only describe evenly spaced beams (a ROS LaserScan, an
albot-log SENSOR line) asks :func:`even_spacing` whether a scan's angles are
``first + i * step``; a format whose 360-degree scans may list their first
direction twice (a LaserScan with ``angle_max = angle_min + 2 pi``, a CARMEN
``ROBOTLASER1`` with a 360-degree field of view over ``n - 1`` steps) asks
:func:`seam_repeat`; formats never import each other (issue 20).
"""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry.types import FloatArray

__all__ = ["ANGLE_SPACING_TOLERANCE", "even_spacing", "seam_note", "seam_repeat"]

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


def seam_repeat(angles: FloatArray) -> bool:
    """True when the last beam points where the first does: a 360-degree scan listed with both ends.

    Several 360-degree drivers publish ``angle_max = angle_min + 2 pi``, so
    beam ``n - 1`` measures the direction of beam 0 a second time. Kept, it is
    one direction counted twice (a duplicated point in every scan-to-map
    match, a zero-length gap where a surface crosses the seam), so the
    loaders drop it. "Points where" means within a quarter of the beam
    spacing: a scanner whose last beam stops one step short of the full turn
    (``angle_max = angle_min + 2 pi - step``) is not a repeat.
    """
    n = angles.shape[0]
    if n < 3:
        return False
    step = abs(float(angles[1] - angles[0]))
    return abs(abs(float(angles[-1] - angles[0])) - 2 * math.pi) <= step / 4


def seam_note(source: str, what: str, beams: int) -> str:
    """The one line a loader logs (once per load) when it drops the repeated last beam of 360-degree scans."""
    return (
        f"{source}: {what}: the last of {beams} beams points where the first does (the beams span exactly "
        f"360 deg); that repeated direction is dropped, leaving {beams - 1} beams per scan"
    )
