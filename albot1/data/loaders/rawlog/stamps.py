"""The stamps a rawlog gives its scans: each scan's own unless MRPT cannot use it.

Why stamps matter to MRPT: ``icp-slam`` keeps the robot pose in a
``CRobot2DPoseEstimator`` (``libs/poses/src/CRobot2DPoseEstimator.cpp`` in
MRPT 2.5). Its ``getLatestRobotPose`` adds the odometry moved since the last
ICP correction only when the latest odometry reading is *strictly newer* than
that correction; otherwise it returns the corrected pose as it was.
``CMetricMapBuilderICP::processObservation``
(``libs/slam/src/slam/CMetricMapBuilderICP.cpp``) measures the distance
travelled since the last ICP with that pose and skips ICP until it exceeds
``localizationLinDistance`` / ``localizationAngDistance``. With every scan at
one stamp (or stamps going back) the odometry is never newer, the distance
never grows, ICP never runs again and the estimate stays where it was: the
path freezes. With a stamp going back now and then, the pose logged (and used
to insert the scan into the map) at that scan leaves out the odometry since
the last correction, and the next ICP comes later. The size of the interval
does not matter to it (no velocities are written, so nothing is extrapolated),
only its sign: each scan's stamp must be strictly later than the previous
scan's, in MRPT's 100 ns ticks, and must not be MRPT's invalid stamp (tick 0).
``rbpf-slam`` copies the stamps of the actions but never compares them.

So a scan keeps its own stamp when it is finite, representable and strictly
later than the stamp written for the previous scan; otherwise it is given the
previous written stamp plus a step: a tenth (:data:`FILL_FRACTION`) of the
interval between the last two scans that kept their own stamps, when there is
one of at most :data:`MAX_LEARNED_STEP_S`, else :data:`NOMINAL_STEP_S`. The
fraction lets the log's own stamps pass the filled ones again a few scans
after a stamp went back (at the log's full interval they never would: the raw
intel log, with 631 stamps going back by up to 0.6 s, would keep its own stamp
on 27 of its first 2,000 scans; with the fraction, on 1,649). A log whose
stamps all qualify is written exactly as before. Each replacement is counted
and the first one is described, so a run can say so.
"""

from __future__ import annotations

from dataclasses import dataclass

from albot1.data.errors import DataError
from albot1.data.loaders.rawlog import serialize

#: Step between filled-in stamps when the log gives no usable interval of its own (s). Any positive value
#: works for MRPT (see the module doc); 1 s is the order of the corrected logs' scan intervals (1.5-5 s).
NOMINAL_STEP_S = 1.0
#: The interval between two kept stamps is used as the step only up to this (s): a jump of hours is not a period.
MAX_LEARNED_STEP_S = 60.0

#: Filled stamps advance by this fraction of the log's own interval (see the module doc).
FILL_FRACTION = 0.1

_NOMINAL_STEP_TICKS = round(NOMINAL_STEP_S * serialize.TICKS_PER_S)
_MAX_LEARNED_STEP_TICKS = round(MAX_LEARNED_STEP_S * serialize.TICKS_PER_S)
#: MRPT's ``INVALID_TIMESTAMP`` (a default ``mrpt::Clock::time_point``).
_INVALID_TICKS = 0
#: Where a clock starts when the first scan's own stamp is unusable: the Unix epoch.
_START_TICKS = serialize.mrpt_timestamp(0.0)


@dataclass
class StampClock:
    """Gives scans their MRPT stamps in order (see the module doc); counts and describes replacements."""

    replaced: int = 0
    #: The first replacement: the scan index, its stamp and why it could not be kept (None: none replaced).
    first_replacement: str | None = None
    _last_ticks: int | None = None
    _last_kept: bool = False
    _step_ticks: int = _NOMINAL_STEP_TICKS

    def stamp(self, index: int, unix_s: float) -> int:
        """The stamp (``mrpt::Clock`` ticks) to write for scan ``index`` whose own stamp is ``unix_s``."""
        problem: str | None = None
        try:
            ticks = serialize.mrpt_timestamp(unix_s)
        except ValueError as exc:
            problem = str(exc)
        else:
            if ticks == _INVALID_TICKS:
                problem = f"timestamp {unix_s!r} is MRPT's invalid timestamp"
            elif self._last_ticks is not None and ticks <= self._last_ticks:
                problem = f"timestamp {unix_s!r} s is not after the previous scan's"
        if problem is None:
            if self._last_kept and self._last_ticks is not None and ticks - self._last_ticks <= _MAX_LEARNED_STEP_TICKS:
                self._step_ticks = max(1, round(FILL_FRACTION * (ticks - self._last_ticks)))
            self._last_ticks, self._last_kept = ticks, True
            return ticks
        filled = _START_TICKS if self._last_ticks is None else self._last_ticks + self._step_ticks
        if filled >= 2**64:
            raise DataError(f"no later MRPT timestamp can follow the previous scan's ({problem})")
        self.replaced += 1
        if self.first_replacement is None:
            self.first_replacement = f"scan {index}: {problem}"
        self._last_ticks, self._last_kept = filled, False
        return filled
