"""Albot1+'s turn bound: a view no landmark places must refute the odometry strongly to turn the robot.

When no recognised landmark places the robot, Albot1+ starts its pose fit from the odometry's prediction
turned by each of :data:`~albot1.methods.albot1.mapping.start_poses.ODOMETRY_TURNS_DEG` (up to 30 deg): a raw odometry
step can be off by tens of degrees, beyond the reach of the scan refinement's nearest-surface matching. Where
the odometry is that bad, the scan says so loudly: the ambiguity test's likelihood ratio of the odometry's
prediction against the turned fit (:mod:`.ambiguity`) is in the hundreds or thousands on aces, intel,
mit-csail and fr079. In a view of a few surfaces (0-2 landmarks, a handful of matched surfaces) a turned start
can also explain the scan only *slightly* better than the odometry's own heading; with an update at every view
such a wrong turn is frozen into the map. fr-clinic's bursts of 10-40 deg while its odometry goes straight
are such views, with ratios of 10-35 (``docs/albot1-mapper.md``, "The turn bound").

The bound uses only what the odometry and the view say. ``turn`` is the odometry's heading change since the
last update view; a view no landmark places whose fit departs from the prediction in heading by more than
``floor + scale * |turn|`` (:func:`allowance`) and whose likelihood ratio is at most ``statistic`` (a turn the
odometry did not make, weakly supported) is fitted again from the starts within that allowance only
(:func:`bounded_starts`); if that fit still departs beyond it, the prediction is the pose. Views a landmark
places are left alone (their starts are the landmarks' own candidate poses). With ``floor = 0``
(``turn_bound_floor_deg``, the default) the bound is off and nothing changes.
"""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry.se2 import wrap_angle
from albot1.geometry.types import FloatArray


def allowance(floor: float, scale: float, turn: float) -> float:
    """The heading departure (rad) from the prediction beyond which a view no landmark places is bounded.

    ``floor`` (rad) and ``scale``: ``turn_bound_floor_deg`` and ``turn_bound_scale``; ``turn`` (rad): the
    odometry's heading change since the last update view. ``floor <= 0``: the bound is off (infinite).
    """
    if floor <= 0.0:
        return math.inf
    return floor + scale * abs(turn)


def beyond(d_phi: float, limit: float) -> bool:
    """Whether a fit ``d_phi`` (rad) from the prediction in heading departs from it further than ``limit``."""
    return abs(wrap_angle(d_phi)) > limit


def bounded_starts(starts: FloatArray, limit: float) -> FloatArray:
    """The rows of ``starts`` ``(c, 3)`` whose heading is within ``limit`` (rad) of the first's (the odometry's).

    The first row, the unturned odometry start, is always kept; the result is contiguous.
    """
    offsets = np.abs((starts[:, 2] - starts[0, 2] + math.pi) % (2.0 * math.pi) - math.pi)
    return np.ascontiguousarray(starts[offsets <= limit + 1e-12])
