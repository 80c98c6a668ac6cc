"""Per-scan poses between graph nodes: interpolation seed, then scan matching against the optimised map.

The graph holds one node per 0.5 m / 28.6 deg of odometry; every other scan
used to get its node's optimised pose composed with the raw odometry since
that node. That pose carries the odometry's error over up to 28.6 deg of
turning, which is what made the relation metric's rotational error grow from
0.43 deg (scans < 1 deg of odometry rotation after their node) to 2.6 deg
(20-40 deg) on ACES (docs/baselines.md, "Why rotations were worse than
published"). Here each scan gets

1. a **seed**: its node's optimised pose composed with the front-end's pose
   of the scan relative to that node (tracked by scan matching, or odometry
   where tracking failed), plus the share of the front-end's disagreement
   with the optimised next node that the scan's progress between the two
   nodes implies (the error is spread along the segment instead of piling
   up at its end);
2. a **refinement**: point-to-line ICP of the scan against the line-like
   points of the surrounding node scans placed at their optimised poses,
   accepted only if it converged, fits (inlier fraction, RMS) and moves the
   seed by a plausible amount; otherwise the seed is kept.

Pure maths on arrays (no GTSAM, no I/O).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from albot1.geometry import se2
from albot1.geometry.types import FloatArray

#: metres of translation that count as much progress as one radian of rotation along a segment
PROGRESS_M_PER_RAD = 1.0


@dataclass(frozen=True)
class RefineTests:
    """Acceptance of a refined scan pose (from the config)."""

    min_fitness: float
    max_rmse_m: float
    max_correction_m: float
    max_correction_rad: float


def progress(offset: FloatArray, step: FloatArray) -> FloatArray:
    """How far along its node-to-node odometry ``step`` (K, 3) each ``offset`` (K, 3) from the first node is, in [0, 1].

    Distance and rotation both count (:data:`PROGRESS_M_PER_RAD`), as
    magnitudes: the fraction survives odometry whose translation has the
    wrong sign.
    """
    off = np.asarray(offset, dtype=float).reshape(-1, 3)
    stp = np.asarray(step, dtype=float).reshape(-1, 3)
    total = np.hypot(stp[:, 0], stp[:, 1]) + PROGRESS_M_PER_RAD * np.abs(stp[:, 2])
    done = np.hypot(off[:, 0], off[:, 1]) + PROGRESS_M_PER_RAD * np.abs(off[:, 2])
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where(total > 0, done / np.where(total > 0, total, 1.0), 0.0)
    return np.clip(fraction, 0.0, 1.0)


def seed_poses(
    nodes: FloatArray, node_steps: FloatArray, scan_node: NDArray[np.int64], scan_offset: FloatArray
) -> FloatArray:
    """The seed pose of every scan (see the module docstring).

    ``nodes`` (N, 3) are optimised node poses, ``node_steps`` (N, 3) the
    front-end's measured pose of each node in the previous node's frame (row
    0 unused), ``scan_node`` (S,) the node each scan belongs to (the last
    node at or before it) and ``scan_offset`` (S, 3) the front-end's pose of
    the scan in that node's frame. Scans after the last node have no next
    node: their seed is the plain composition.
    """
    nodes = np.asarray(nodes, dtype=float)
    node_steps = np.asarray(node_steps, dtype=float)
    scan_node = np.asarray(scan_node, dtype=np.int64)
    scan_offset = np.asarray(scan_offset, dtype=float)
    seeds = se2.compose(nodes[scan_node], scan_offset)
    inner = np.flatnonzero(scan_node < len(nodes) - 1)
    if not len(inner):
        return seeds
    k = scan_node[inner]
    steps = node_steps[k + 1]
    optimised = se2.between(nodes[k], nodes[k + 1])
    disagreement = se2.between(steps, optimised)  # what the measured step misses, in the frame of its end
    share = disagreement * progress(scan_offset[inner], steps)[:, None]
    seeds[inner] = se2.compose(se2.compose(nodes[k], scan_offset[inner]), share)
    return seeds


def accept(
    tests: RefineTests, seed: FloatArray, pose: FloatArray, converged: bool, fitness: float, rmse_m: float
) -> bool:
    """Whether a refined pose may replace its seed."""
    if not converged or fitness < tests.min_fitness or rmse_m > tests.max_rmse_m:
        return False
    corr = se2.between(seed, pose)
    return bool(math.hypot(corr[0], corr[1]) <= tests.max_correction_m and abs(corr[2]) <= tests.max_correction_rad)
