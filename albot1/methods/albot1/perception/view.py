"""View construction (thesis 3.1.3): from one laser scan to ordered line surfaces.

The five steps of the thesis (point filtering, clustering, recursive
segmenting, surface forming, surface filtering) run in one compiled pass
(:func:`albot1.methods.albot1.perception.kernels.build_view`), which also labels each
surface endpoint (occluding, corner, ...; 3.1.4) because that needs the raw
beams the view itself no longer holds. Readings of "cluster size" and the
split rule are documented on :class:`ViewParams`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.albot1.perception.kernels import PerceptionKernels

IntArray = NDArray[np.int64]


@dataclass(frozen=True, slots=True)
class ViewParams:
    """Thresholds of 3.1.3 and of the endpoint labels of 3.1.4 (metres, radians).

    ``cluster_size`` is compared with the chord from a cluster's first to its
    last point (a point count worked worse); a cluster longer than that is
    split at its point farthest from the chord when that distance exceeds
    ``break_point_height``, the split point ending one half and starting the
    other, recursively (iterative end-point fit). ``corner_min_turn`` is the
    smallest turn between two pieces of one cluster that makes their shared
    point a corner (the thesis gives none); ``occlusion_margin`` is how much
    farther the next return outward must be for a cluster end to occlude.
    ``end_spacing_max`` (0 = off) makes an occluding or corner end unstable
    where the next point on its surface is farther than that (a grazing
    view); ``fit_lines`` forms surfaces by total least squares with corners
    at the intersection of neighbouring lines instead of the chord.
    """

    max_range: float = 30.0
    cluster_gap: float = 0.6
    cluster_size: float = 0.2
    break_point_height: float = 0.1
    surface_length: float = 0.1
    corner_min_turn: float = math.radians(30.0)
    occlusion_margin: float = 0.0
    continuation_tolerance: float = 0.1
    end_spacing_max: float = 0.0
    end_spacing_grazing: float = 0.0
    fit_lines: bool = False


@dataclass(frozen=True, slots=True)
class View:
    """Surfaces of one scan in the thesis frame, left to right.

    ``surfaces`` ``(m, 4)``: P1 (x1, y1) is the surface's left end, P2 its
    right end. ``kinds`` ``(m, 2)``: label of P1 and P2 (see
    :mod:`albot1.methods.albot1.perception.endpoints`). ``beams`` ``(m, 2)``: index of the
    endpoint's beam counted from the left. ``cluster`` ``(m,)``: the cluster
    each surface was cut from.
    """

    surfaces: FloatArray
    kinds: IntArray
    beams: IntArray
    cluster: IntArray

    def __len__(self) -> int:
        return int(self.surfaces.shape[0])

    @property
    def lengths(self) -> FloatArray:
        s = self.surfaces
        return np.hypot(s[:, 2] - s[:, 0], s[:, 3] - s[:, 1])


def seam_at_gap(ranges: FloatArray, angles: FloatArray, max_range: float) -> tuple[FloatArray, FloatArray]:
    """A full-turn scan's beams restarted at its widest gap between returns; any other scan as it is.

    A view treats a scan's beams as an arc with two ends: a surface cannot run past the first or last beam,
    and an end there is unstable (the field of view cuts it). A 360-degree scanner has no such edge, but its
    beams still begin somewhere (a TurtleBot's LDS-01 at 0 deg, straight ahead), so a wall across that seam
    was cut in two with two unstable ends where it is continuous. The seam is moved to the widest gap
    between consecutive returns (circularly; beams without a return, as step 1 of the view drops them, do
    not count), where clustering would break the wall anyway when the gap exceeds the cluster gap. The
    beams from there to the end are put first and the rest after them, their angles 2 pi on, so angles still
    ascend. A scan is a full turn when the gap its beams leave between the last and the first is at most
    1.5 of their mean spacing.
    """
    n = angles.shape[0]
    if n < 3:
        return ranges, angles
    span = float(angles[-1] - angles[0])
    if not (0.0 < span and 2.0 * math.pi - span <= 1.5 * span / (n - 1)):
        return ranges, angles
    with np.errstate(invalid="ignore"):
        hit = np.flatnonzero(np.isfinite(ranges) & (ranges > 0.0) & (ranges <= max_range))
    if hit.size < 2:
        return ranges, angles
    x, y = ranges[hit] * np.cos(angles[hit]), ranges[hit] * np.sin(angles[hit])
    gaps = np.hypot(np.roll(x, -1) - x, np.roll(y, -1) - y)  # return k to return k + 1, the last to the first
    start = int(hit[(int(np.argmax(gaps)) + 1) % hit.size])
    if start == 0:
        return ranges, angles
    turned = np.concatenate([angles[start:], angles[:start] + 2.0 * math.pi])
    return np.concatenate([ranges[start:], ranges[:start]]), turned


def construct_view(
    ranges: FloatArray, angles: FloatArray, params: ViewParams, kernels: PerceptionKernels | None = None
) -> View:
    """``constructView`` of Algorithm 4 for a REP-103 scan (angles ascending, counter-clockwise).

    The thesis orders surfaces left to right, i.e. by *descending* beam
    angle, so the beams are reversed before the pass. A 360-degree scan
    starts at its widest gap (:func:`seam_at_gap`); ``View.beams`` then count
    from there.
    """
    k = kernels or PerceptionKernels()
    ranges, angles = seam_at_gap(
        np.asarray(ranges, dtype=np.float64), np.asarray(angles, dtype=np.float64), params.max_range
    )
    r = np.ascontiguousarray(ranges[::-1])  # float64 already (above)
    a = np.ascontiguousarray(angles[::-1])
    surfaces, kinds, beams, cluster = k.build_view(
        r,
        a,
        params.max_range,
        params.cluster_gap,
        params.cluster_size,
        params.break_point_height,
        params.surface_length,
        params.corner_min_turn,
        params.occlusion_margin,
        params.continuation_tolerance,
        params.end_spacing_max,
        params.end_spacing_grazing,
        params.fit_lines,
    )
    return View(surfaces, kinds, beams, cluster)
