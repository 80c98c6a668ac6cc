"""The constant-velocity guess scaled by the time between scans (``track_velocity_time_scaled``).

The tracker's velocity guess (:meth:`.frontend.FrontEnd.follow`) is the last
tracked scan-to-scan motion, reused as is for the next scan: a velocity per
*scan*. Where the time between kept scans varies (scan dropout, ``[::k]``
strides, irregular logs) that is not the textbook constant-velocity model,
which follows the last motion's twist for as long as the new step lasts:
``exp((dt_now / dt_last) * log(motion))`` (:func:`albot1.geometry.se2.scale_motion`).
On logs with scans dropped the per-scan guess lies metres short of a long
odometry step (docs/baselines.md, gtsam-graph, "an outsider's sweep").

Timestamps can lie: the SLAM-corrected logs carry none (every stamp 0),
intel's go back 631 times, infinite-corridor-corrected's wrap around 2**32,
fr-clinic pauses for 198 s. So the ratio is used only when both elapsed times
are finite and positive (else the guess stays the per-scan one: no division
by zero, no sign flip from a stamp going back), and it is clamped to
``[1 / max_ratio, max_ratio]``: a clock that jumps cannot send the guess
metres or turns away, and the guess is only a start for ICP, tested like any
other.
"""

from __future__ import annotations

import math

from albot1.geometry import se2
from albot1.geometry.types import FloatArray


def elapsed(stamp: float | None, previous: float | None) -> float:
    """Seconds from ``previous`` to ``stamp``; NaN when either is unknown (the ratio then stays 1)."""
    if stamp is None or previous is None:
        return math.nan
    return float(stamp) - float(previous)


def time_ratio(dt_now: float, dt_last: float, max_ratio: float) -> float:
    """``dt_now / dt_last`` clamped to ``[1 / max_ratio, max_ratio]``; 1 unless both are finite and positive.

    A zero, negative or unknown elapsed time (repeated, backward or missing
    stamps) says nothing about the motion's speed, so the per-scan velocity
    stands, exactly as with the setting off.
    """
    if not (math.isfinite(dt_now) and math.isfinite(dt_last) and dt_now > 0.0 and dt_last > 0.0):
        return 1.0
    return min(max_ratio, max(1.0 / max_ratio, dt_now / dt_last))


def scaled_velocity(velocity: FloatArray, dt_now: float, dt_last: float, max_ratio: float) -> FloatArray:
    """The last motion ``velocity`` (over ``dt_last`` s) followed for ``dt_now`` s at the same twist."""
    return se2.scale_motion(velocity, time_ratio(dt_now, dt_last, max_ratio))
