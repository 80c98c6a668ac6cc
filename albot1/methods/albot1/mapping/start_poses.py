"""Albot1+'s start poses: where the robust pose fit starts (it keeps the cheapest start).

A module of its own because two callers build them: :mod:`.plus` (the odometry turned, when no landmark places
the robot) and the mapper's compiled localisation (:func:`.localise_kernels.robust_starts`, which takes
:data:`ODOMETRY_TURNS` as an argument and must start from the same poses).
"""

from __future__ import annotations

import numpy as np

from albot1.geometry.se2 import Pose
from albot1.geometry.types import FloatArray

#: Heading offsets (deg) tried around the odometry when no landmark places the robot: a raw odometry step can be
#: off by tens of degrees on a turn, beyond the reach of the scan refinement's nearest-surface matching.
ODOMETRY_TURNS_DEG = (0.0, -3.0, 3.0, -6.0, 6.0, -10.0, 10.0, -15.0, 15.0, -20.0, 20.0, -30.0, 30.0)

#: :data:`ODOMETRY_TURNS_DEG` in radians (the start poses' turns, here and in ``robust_starts``' caller)
ODOMETRY_TURNS = np.radians(np.asarray(ODOMETRY_TURNS_DEG))


def start_poses(odometry: Pose, thesis: Pose | None, candidates: FloatArray | list[Pose] | None) -> FloatArray:
    """The poses the solver starts from (it keeps the cheapest): ``(c, 3)``, contiguous.

    With a thesis localisation: its pose, the odometry step and every
    landmark's candidate pose (one mismatched landmark cannot then decide
    alone). Without: the odometry step turned by each of
    :data:`ODOMETRY_TURNS_DEG`. ``candidates``: ``(c, 3)``, or the poses as localisation listed them
    (:attr:`~albot1.methods.albot1.mapping.localisation.Localisation.poses`; one array built, not two).
    """
    # Filled in place (values as the stacked arrays had them): numpy's stacking calls cost more than the copies.
    if thesis is None or candidates is None:
        starts = np.empty((ODOMETRY_TURNS.size, 3))
        starts[:, 0] = odometry[0]
        starts[:, 1] = odometry[1]
        starts[:, 2] = odometry[2] + ODOMETRY_TURNS
        return starts
    if isinstance(candidates, list):  # the same float64 values, from Python floats in one call
        return np.array([thesis, odometry, *candidates], dtype=float).reshape(-1, 3)
    others = np.asarray(candidates, dtype=float).reshape(-1, 3)
    starts = np.empty((2 + others.shape[0], 3))
    starts[0] = thesis
    starts[1] = odometry
    starts[2:] = others
    return starts
