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

So a scan keeps its own stamp when it is finite, representable in MRPT's
ticks, not tick 0 and strictly later than the stamp *written* for the
previous scan (kept or filled); otherwise it is given that written stamp plus
:data:`~albot1.data.retime.RETIME_STEP_S` (1 us, 10 ticks): the rule
``albot1 convert --retime`` uses (:func:`albot1.data.retime.next_stamp`), so
each stamp moves only as far as needed and the log's own stamps take over
again as soon as they pass the filled ones. When the first scan's stamp is
unusable the clock starts at the Unix epoch (:data:`START_S`). A log whose
stamps all qualify is written exactly as before. Each replacement is counted
and the first one is described, so a run can say so.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from albot1.data.errors import DataError
from albot1.data.loaders.rawlog import serialize
from albot1.data.retime import RETIME_STEP_S, next_stamp

#: Where the clock starts when the first scan's own stamp is unusable (Unix seconds): the Unix epoch.
START_S = 0.0

#: :data:`~albot1.data.retime.RETIME_STEP_S` in ``mrpt::Clock`` ticks.
STEP_TICKS = round(RETIME_STEP_S * serialize.TICKS_PER_S)
#: MRPT's ``INVALID_TIMESTAMP`` (a default ``mrpt::Clock::time_point``).
_INVALID_TICKS = 0
_START_TICKS = serialize.mrpt_timestamp(START_S)


@dataclass
class StampClock:
    """Gives scans their MRPT stamps in order (see the module doc); counts and describes replacements."""

    replaced: int = field(default=0, init=False)
    #: The first replacement: the scan index, its stamp and why it could not be kept (None: none replaced).
    first_replacement: str | None = field(default=None, init=False)
    #: The stamp written for the previous scan (None before the first).
    _last_ticks: int | None = field(default=None, init=False)

    def stamp(self, index: int, unix_s: float) -> int:
        """The stamp (``mrpt::Clock`` ticks) to write for scan ``index`` whose own stamp is ``unix_s``."""
        problem: str | None = None
        written = _START_TICKS if self._last_ticks is None else self._last_ticks + STEP_TICKS
        try:
            ticks = serialize.mrpt_timestamp(unix_s)
        except ValueError as exc:
            problem = str(exc)
        else:
            if ticks == _INVALID_TICKS:
                problem = f"timestamp {unix_s!r} is MRPT's invalid timestamp"
            else:
                written = next_stamp(ticks, self._last_ticks, step=STEP_TICKS, resolution=1)
                if written != ticks:
                    problem = f"timestamp {unix_s!r} s is not after the previous scan's"
        if problem is not None:
            if written >= 2**64:
                raise DataError(f"no later MRPT timestamp can follow the previous scan's ({problem})")
            self.replaced += 1
            if self.first_replacement is None:
                self.first_replacement = f"scan {index}: {problem}"
        self._last_ticks = written
        return written
