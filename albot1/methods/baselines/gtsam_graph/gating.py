"""Gating tracked scans against the odometry: the velocity guess may not overrule a passing odometry match by a
turn the odometry does not allow, and a correction far beyond the recent ones must fit clearly.

The tracker also starts ICP from the constant-velocity guess (the last
tracked scan-to-scan motion) when it disagrees with the odometry guess,
for logs whose odometry stalls and then catches up (mit-csail repeats its
odometry on 87 scans and then jumps by up to 0.95 m and 85 deg); the better
fit wins. Where the odometry is right that is a gamble on fit alone: on
fhw-corrected with perfect odometry the robot turns +63 deg in place, the
odometry guess gave a passing match, and the velocity guess (the previous
motion) gave a match 95 deg away that fitted better (inlier fraction 0.65
against 0.49); its -31.5 deg turn bent the whole map (ATE 11.1 m).

The rule: when the odometry guess itself produced a passing match, the
velocity match may replace it only if its heading stays within the widest
correction the tracker allows any match to make to the odometry's heading
(``track_wide_correction_deg``, shrinking to ``seq_max_correction_deg`` for
node-length increments). When the odometry match failed (a stalled
odometry's catch-up jump: on mit-csail the velocity matches that won there
turned the odometry guess by 42 and 70 deg), the velocity match is judged
on its own tests as before.
"""

from __future__ import annotations

import math
from collections import deque
from statistics import median

from albot1.geometry import se2
from albot1.geometry.types import FloatArray


def odometry_stalled(increment: FloatArray, previous_increment: FloatArray | None) -> bool:
    """Whether this scan's or the previous scan's odometry increment is exactly zero (a repeated reading).

    A stalled odometry repeats its last reading, so the increment is exactly
    (0, 0, 0), not merely small (a robot standing still with wheel odometry
    still reads noise). During the stall the velocity guess holds the motion
    the odometry missed; at the catch-up step (the first increment after a
    repeat) the odometry guess, applied to a tracked pose that already moved,
    overshoots. With a moving odometry there is nothing for the tracked
    velocity to recover: on logs with scans dropped its guess lies metres
    short of a right odometry guess (docs/baselines.md, gtsam-graph, "an
    outsider's sweep").
    """
    return not increment.any() or (previous_increment is not None and not previous_increment.any())


def turn_agrees(pose: FloatArray, odometry_guess: FloatArray, max_turn_deg: float) -> bool:
    """Whether ``pose`` turns ``odometry_guess`` by at most ``max_turn_deg`` (both in the same frame)."""
    return abs(float(se2.between(odometry_guess, pose)[2])) <= math.radians(max_turn_deg)


def velocity_match_allowed(
    velocity_pose: FloatArray, odometry_guess: FloatArray, odometry_match_passed: bool, max_turn_deg: float
) -> bool:
    """Whether a passing match from the velocity guess may compete with the odometry guess's (module docstring)."""
    return not odometry_match_passed or turn_agrees(velocity_pose, odometry_guess, max_turn_deg)


class CorrectionScale:
    """How far tracking matches have recently moved their guesses: a tracked correction far beyond that is suspect.

    The odometry's error is what tracking corrects, so the corrections of
    recent passing matches measure it (the median over the last ``window``
    tracked scans, translation and rotation apart, never below the match
    floors). A correction more than ``factor`` times that scale is an
    outlier of the innovation sequence: either the odometry just went wrong
    (mit-csail's odometry turns 20 deg wrong within 0.4 s while the robot
    spins; those matches explain 0.8-0.99 of the scan) or the match did (on
    fhw-corrected with perfect odometry, an in-place turn of 63 deg matched
    0.23 m / 6 deg off with half the scan explained, 0.49, and corrupted
    the local map the next scans matched against). An outlier is therefore
    trusted only when the match fits clearly; else the odometry guess
    stands. Until ``window // 5`` corrections are known nothing is an outlier.
    """

    def __init__(self, window: int, floor_m: float, floor_deg: float) -> None:
        self._history: deque[tuple[float, float]] = deque(maxlen=window)
        self._min_history = max(1, window // 5)
        self._floor_m = floor_m
        self._floor_rad = math.radians(floor_deg)

    def is_outlier(self, correction: FloatArray, factor: float) -> bool:
        """Whether ``correction`` (x, y, theta) exceeds ``factor`` times the recent scale (``factor <= 0``: never)."""
        if factor <= 0 or len(self._history) < self._min_history:
            return False
        scale_m = max(self._floor_m, median(h[0] for h in self._history))
        scale_rad = max(self._floor_rad, median(h[1] for h in self._history))
        return math.hypot(correction[0], correction[1]) > factor * scale_m or abs(correction[2]) > factor * scale_rad

    def add(self, correction: FloatArray) -> None:
        """Record the correction of a passing match."""
        self._history.append((math.hypot(correction[0], correction[1]), abs(float(correction[2]))))
