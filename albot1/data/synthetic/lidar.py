"""A simulated planar laser scanner: exact ray casting against wall segments.

The maths is pure numpy and has no I/O. Each wall is intersected only with the
beams inside the angular interval it subtends from the sensor (a binary
search on the sorted beam angles), so the work per scan is beams x depth
complexity rather than beams x walls, and all (beam, wall) pairs of a batch
of poses are solved as flat numpy arrays. A 181-beam scan against a few
hundred segments takes a fraction of a millisecond, which is what lets the
embedded worlds be generated on first use instead of being shipped as files.

Conventions (the data model of ``docs/architecture.md``, ROS REP-103): beam angles are radians,
counter-clockwise, 0 = straight ahead, ascending; a 180-degree, 181-beam
scanner (the thesis's SICK LMS-200 at 1 degree) has beam 0 at -90 degrees
(the robot's right). A beam that hits nothing within ``max_range`` reads NaN
("no return"), which is how every loader in the suite encodes max-range
readings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from albot1.data.synthetic.errors import SyntheticWorldError
from albot1.geometry.types import FloatArray

# A hit closer than this to the ray origin is treated as the origin touching a
# wall (the sensor is never placed inside a wall), not as a return.
_MIN_HIT = 1e-9
# Tolerances that keep a beam aimed exactly at a corner from slipping between
# the two walls meeting there through floating-point rounding.
_ANGLE_SLACK = 1e-9
_PARAM_SLACK = 1e-9


@dataclass(frozen=True)
class LaserSpec:
    """Beam geometry and error model of the simulated scanner.

    ``range_sigma`` is the standard deviation (m) of zero-mean Gaussian range
    noise; the SICK LMS-200 datasheet gives about 1 cm at indoor ranges.
    ``max_range`` defaults to the thesis's 30 m filter threshold, so what the
    simulated robot sees is what Albot1 would keep.
    """

    beams: int = 181
    fov_deg: float = 180.0
    max_range: float = 30.0
    range_sigma: float = 0.01

    def __post_init__(self) -> None:
        if self.beams < 2:
            raise SyntheticWorldError(f"laser: expected at least 2 beams, got {self.beams}")
        if not 0.0 < self.fov_deg <= 360.0:
            raise SyntheticWorldError(f"laser: expected a field of view in (0, 360] deg, got {self.fov_deg}")
        if not (math.isfinite(self.max_range) and self.max_range > 0):
            raise SyntheticWorldError(f"laser: expected a positive finite max range, got {self.max_range}")
        if not (math.isfinite(self.range_sigma) and self.range_sigma >= 0):
            raise SyntheticWorldError(f"laser: expected a range sigma >= 0, got {self.range_sigma}")

    @property
    def full_turn(self) -> bool:
        """A 360-degree scanner: its beams split the turn into ``beams`` equal steps, none measured twice."""
        return self.fov_deg == 360.0

    @property
    def angles(self) -> FloatArray:
        """Beam angles (rad), ascending; symmetric about 0 (forward) for a field of view under 360 deg.

        A 360-degree scanner starts at -180 deg and stops one step short of
        +180 deg: spreading its beams from -180 to +180 deg would aim the last
        beam where the first points, one direction measured twice.
        """
        if self.full_turn:
            return -math.pi + np.arange(self.beams, dtype=np.float64) * (2 * math.pi / self.beams)
        half = math.radians(self.fov_deg) / 2.0
        return np.linspace(-half, half, self.beams)

    @property
    def resolution_deg(self) -> float:
        return self.fov_deg / (self.beams if self.full_turn else self.beams - 1)


def as_segments(walls: ArrayLike) -> FloatArray:
    """Walls as a float ``(M, 4)`` array of ``x1, y1, x2, y2`` rows, or SyntheticWorldError."""
    seg = np.asarray(walls, dtype=float)
    if seg.ndim != 2 or seg.shape[1] != 4:
        raise SyntheticWorldError(f"expected wall segments of shape (M, 4) (x1, y1, x2, y2), got {seg.shape}")
    return seg


def cast(walls: ArrayLike, pose: ArrayLike, angles: ArrayLike, max_range: float) -> FloatArray:
    """Exact ranges of one scan taken at ``pose`` (x, y, theta): NaN where no wall is within ``max_range``.

    The sensor sits at the pose's origin looking along its heading; ``angles``
    must be ascending, in any range (0 to 2 pi as well as -pi to pi). Walls
    are two-sided: a ray stops at the first segment it meets, whichever side.
    A ray running exactly along a wall does not hit it (zero-thickness walls
    have no end face); in a closed plan it stops at the next wall meeting that
    one at a corner.
    """
    ranges: FloatArray = cast_many(walls, np.asarray(pose, dtype=float).reshape(1, 3), angles, max_range)[0]
    return ranges


def cast_many(
    walls: ArrayLike, poses: ArrayLike, angles: ArrayLike, max_range: float, *, batch: int = 16
) -> FloatArray:
    """Exact ranges ``(N, beams)`` for ``N`` poses (see :func:`cast`).

    Rather than intersecting every beam with every wall, each wall is only
    tested against the beams inside the angular interval it subtends from the
    pose (found by binary search), so the work grows with beams x depth
    complexity instead of beams x walls. Poses are processed in batches so
    the per-call overhead of numpy is shared by several scans; small batches
    (16) keep the pair arrays in cache, and measured faster than large ones.
    """
    seg = as_segments(walls)
    p = np.asarray(poses, dtype=float).reshape(-1, 3)
    beam = np.asarray(angles, dtype=float)
    if beam.ndim != 1 or np.any(np.diff(beam) < 0):
        raise SyntheticWorldError("laser: beam angles must be a 1-D ascending array")
    outside = (beam < -math.pi) | (beam > math.pi)
    if outside.any():
        # Walls are found by their bearings in [-pi, pi]; a beam given beyond them (a 360-degree scanner
        # from 0 to 359 deg, as a TurtleBot's LDS-01 reports) is cast at its bearing there and put back in
        # its place. Such beams used to find no wall at all: every beam past 180 deg read "no return".
        wrapped = np.where(outside, np.remainder(beam + math.pi, 2.0 * math.pi) - math.pi, beam)
        order = np.argsort(wrapped, kind="stable")
        ranges = np.empty((len(p), len(beam)))
        ranges[:, order] = cast_many(seg, p, wrapped[order], max_range, batch=batch)
        return ranges
    out = np.full((len(p), len(beam)), np.inf)
    if len(seg) and len(beam):
        cos_b, sin_b = np.cos(beam), np.sin(beam)
        for start in range(0, len(p), batch):
            _cast_batch(out[start : start + batch], seg, p[start : start + batch], beam, cos_b, sin_b)
    out[~(out <= max_range)] = np.nan
    return out


def _cast_batch(
    out: FloatArray, seg: FloatArray, poses: FloatArray, beam: FloatArray, cos_b: FloatArray, sin_b: FloatArray
) -> None:
    """Fill ``out`` (n, beams), initialised to inf, with the nearest hit per beam for ``n`` poses."""
    m, beams = len(seg), len(beam)
    # Walls in each sensor frame, shape (n, m), so beam directions depend on the beam only.
    c, s = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
    px, py = seg[:, 0] - poses[:, 0:1], seg[:, 1] - poses[:, 1:2]
    qx, qy = seg[:, 2] - poses[:, 0:1], seg[:, 3] - poses[:, 1:2]
    ax, ay = (c * px + s * py).ravel(), (-s * px + c * py).ravel()
    bx, by = (c * qx + s * qy).ravel(), (-s * qx + c * qy).ravel()
    pair_idx, lo, hi = _angular_intervals(ax, ay, bx, by)
    first = np.searchsorted(beam, lo, side="left")
    counts = np.maximum(np.searchsorted(beam, hi, side="right") - first, 0)
    total = int(counts.sum())
    if not total:
        return
    wall = np.repeat(pair_idx, counts)  # index into the flattened (n, m) walls
    starts = np.cumsum(counts) - counts
    ray = np.arange(total) - np.repeat(starts - first, counts)
    cell = (wall // m) * beams + ray  # index into the flattened (n, beams) output
    _nearest_hits(out.reshape(-1), cell, ax[wall], ay[wall], bx[wall], by[wall], cos_b[ray], sin_b[ray])


def _angular_intervals(
    ax: FloatArray, ay: FloatArray, bx: FloatArray, by: FloatArray
) -> tuple[NDArray[np.intp], FloatArray, FloatArray]:
    """``(wall index, lo, hi)`` bearing intervals in ``[-pi, pi]`` each wall covers.

    A wall not through the sensor subtends less than pi, so its interval is
    the short arc between its end bearings; one that straddles the backward
    direction (+-pi) is split in two. Intervals are widened by a few
    nano-radians so a beam aimed exactly at a corner is still tested against
    both walls meeting there (the exact test below decides).
    """
    alpha = np.arctan2(ay, ax)
    beta = np.arctan2(by, bx)
    lo, hi = np.minimum(alpha, beta), np.maximum(alpha, beta)
    wraps = hi - lo > math.pi
    idx = np.arange(len(ax))
    if not wraps.any():
        return idx, lo - _ANGLE_SLACK, hi + _ANGLE_SLACK
    eps = _ANGLE_SLACK
    all_idx = np.concatenate([idx[~wraps], idx[wraps], idx[wraps]])
    all_lo = np.concatenate([lo[~wraps] - eps, hi[wraps] - eps, np.full(int(wraps.sum()), -math.pi)])
    all_hi = np.concatenate([hi[~wraps] + eps, np.full(int(wraps.sum()), math.pi), lo[wraps] + eps])
    return all_idx, all_lo, all_hi


def _nearest_hits(
    out: FloatArray,
    cell: NDArray[np.intp],
    ax: FloatArray,
    ay: FloatArray,
    bx: FloatArray,
    by: FloatArray,
    dx: FloatArray,
    dy: FloatArray,
) -> None:
    """Lower ``out[cell]`` to the distance at which each (ray, wall) pair's ray (direction dx, dy) meets the wall."""
    ex, ey = bx - ax, by - ay
    den = dx * ey - dy * ex  # cross(d, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (ax * ey - ay * ex) / den  # cross(a, e) / cross(d, e): distance along the ray
        u = (ax * dy - ay * dx) / den  # cross(a, d) / cross(d, e): position along the wall
    hit = (t > _MIN_HIT) & (u >= -_PARAM_SLACK) & (u <= 1.0 + _PARAM_SLACK)
    np.minimum.at(out, cell[hit], t[hit])


def add_noise(ranges: ArrayLike, sigma: float, max_range: float, rng: np.random.Generator) -> FloatArray:
    """``ranges`` plus zero-mean Gaussian noise; readings pushed past ``max_range`` become NaN.

    Noise is drawn for every beam (NaN or not) so the stream of random numbers
    does not depend on what the scan saw, which keeps worlds reproducible when
    a wall moves. Negative results are clipped to 0.
    """
    r = np.asarray(ranges, dtype=float)
    noisy: FloatArray = r + rng.normal(0.0, sigma, size=r.shape) if sigma > 0 else r.copy()
    noisy = np.maximum(noisy, 0.0)
    noisy[~(noisy <= max_range)] = np.nan
    return noisy
