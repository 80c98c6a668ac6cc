"""A small synthetic room and an exact ray caster, for the KISS-ICP unit tests.

The room is an 8 m x 6 m rectangle with a box and two slanted walls inside,
so every registration is well constrained in x, y and heading. Ranges are
exact (no noise): the only error left in a registration is the method's own.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.data.model import Frame, Scan
from albot1.geometry import se2

FloatArray = NDArray[np.float64]

WALLS = np.array(
    [
        [0, 0, 8, 0],
        [8, 0, 8, 6],
        [8, 6, 0, 6],
        [0, 6, 0, 0],  # outer walls
        [2, 2, 3, 2],
        [3, 2, 3, 3],
        [3, 3, 2, 3],
        [2, 3, 2, 2],  # a 1 m box
        [5, 4, 6.5, 4.5],
        [6, 1, 7, 1.5],  # two slanted walls
    ],
    dtype=float,
)


def scan_at(pose: FloatArray, beams: int = 720, max_range: float = 30.0, timestamp: float = 0.0) -> Scan:
    """A 360-degree scan from ``pose`` (x, y, theta) against :data:`WALLS`; NaN where nothing is hit."""
    angles = np.linspace(-math.pi, math.pi, beams, endpoint=False)
    start, end = WALLS[:, :2], WALLS[:, 2:]
    edge = end - start  # (W, 2)
    offset = start - np.asarray(pose[:2], dtype=float)
    dx, dy = np.cos(angles + pose[2])[:, None], np.sin(angles + pose[2])[:, None]  # (B, 1)
    den = dx * edge[:, 1] - dy * edge[:, 0]  # (B, W): ray x edge
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (offset[:, 0] * edge[:, 1] - offset[:, 1] * edge[:, 0]) / den  # distance along the ray
        u = (offset[:, 0] * dy - offset[:, 1] * dx) / den  # position along the wall
    hit = (np.abs(den) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
    ranges = np.where(hit, t, np.inf).min(axis=1)
    ranges[~np.isfinite(ranges)] = np.nan
    return Scan(ranges, angles, timestamp, max_range)


def route(n: int = 30) -> FloatArray:
    """``n`` true poses along a smooth path around the box, clear of every wall."""
    s = np.linspace(0.0, 1.0, n)
    x = 4.0 + 2.6 * np.cos(2 * math.pi * 0.8 * s - math.pi / 2) * 0.9
    y = 2.9 + 1.9 * np.sin(2 * math.pi * 0.8 * s - math.pi / 2) * 0.9
    theta = np.unwrap(np.arctan2(np.gradient(y), np.gradient(x)))
    return np.column_stack([x, y, se2.wrap(theta)])


def noisy_odometry(truth: FloatArray, sigma_xy: float, sigma_deg: float, seed: int) -> FloatArray:
    """Odometry from the true steps plus zero-mean Gaussian step noise (seeded)."""
    rng = np.random.default_rng(seed)
    steps = se2.relative_steps(truth)
    steps = steps + rng.normal(0.0, 1.0, steps.shape) * [sigma_xy, sigma_xy, math.radians(sigma_deg)]
    return se2.integrate_steps(truth[0], steps)


def frames(truth: FloatArray, odometry: FloatArray, beams: int = 720) -> list[Frame]:
    """Frames scanning the room from ``truth`` and carrying ``odometry``, 0.1 s apart."""
    return [
        Frame(i, scan_at(p, beams, timestamp=0.1 * i), np.asarray(o, dtype=float), np.asarray(p, dtype=float))
        for i, (p, o) in enumerate(zip(truth, odometry))
    ]
