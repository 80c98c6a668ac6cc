"""Making stamps strictly increasing, moving each only as far as needed: the rule ``albot1 convert --retime``
(:func:`albot1.data.convert.retimed`) and the MRPT rawlog's stamp fill (:mod:`albot1.data.loaders.rawlog.stamps`)
share, so a converted log and an MRPT run agree on which stamps move and where to.

A stamp at least ``resolution`` after the previous one (the one *written* for the previous scan, moved or not)
is kept; otherwise it becomes the previous one plus :data:`RETIME_STEP_S`. Nothing else moves: later stamps
that are after the moved one keep their own values, so a stamp going back shifts only the scans until the log's
own stamps pass the moved ones again.
"""

from __future__ import annotations

from typing import TypeVar

#: The smallest step a moved stamp is put after the previous one: 1 us is representable at Unix-epoch
#: magnitudes (float64 spacing there ~ 0.2 us), far above a bag's 1 ns clock, and 10 of MRPT's 100 ns ticks.
RETIME_STEP_S = 1e-6

#: Seconds (float) or a clock's integer ticks.
Stamp = TypeVar("Stamp", int, float)


def next_stamp(own: Stamp, previous: Stamp | None, *, step: Stamp, resolution: Stamp) -> Stamp:
    """``own`` when there is no ``previous`` or ``own`` is at least ``resolution`` after it; else ``previous + step``.

    ``step`` is :data:`RETIME_STEP_S` in the caller's unit; ``resolution`` is the smallest difference the
    caller's clock keeps apart (``step`` itself for float seconds, 1 for integer ticks). A NaN ``own`` is
    returned unchanged (it compares as not before anything); callers that cannot use one check it first.
    """
    if previous is not None and own < previous + resolution:
        return previous + step
    return own
