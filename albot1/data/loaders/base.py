"""The explicit protocols every file-format loader and writer implements.

The registry asks a loader ``sniff(path)`` (a cheap look at the file's
signature) instead of probing attributes; ``load`` returns a streamed
:class:`~albot1.data.model.Sequence` and raises only
:class:`~albot1.data.errors.DataError` subclasses.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, ClassVar, Protocol, runtime_checkable

from albot1.config.suggest import closest
from albot1.data.errors import DataError
from albot1.data.model import Frame, Sequence

#: The options every source takes besides its loader's own (applied by :mod:`albot1.data.open` and
#: :mod:`albot1.data.attach`, not by a loader): loaders name them in their unknown-option errors.
COMMON_OPTIONS = ("relations", "relations_repeats", "reference", "reference_max_dt", "odometry=reference", "views")

#: Values of ``reference`` that a CARMEN log reads as a keyword (which lines hold the reference), not as a file
#: name (:mod:`albot1.data.attach` attaches every other value as a trajectory file).
REFERENCE_KEYWORDS = ("none", "laser-pose", "truepos", "auto")


def option_names(own: tuple[str, ...] | list[str]) -> list[str]:
    """A loader's own options, then each of :data:`COMMON_OPTIONS` it does not take itself, every name once.

    A CARMEN log takes ``reference`` and ``odometry`` itself: its unknown-option error listed ``reference``
    twice and ``odometry=reference`` beside ``odometry``.
    """
    taken = set(own)
    return [*own, *(name for name in COMMON_OPTIONS if name.partition("=")[0] not in taken)]


def unknown_option_hint(unknown: list[str], names: list[str]) -> str:
    """``" (did you mean 'odometry' for 'odometr'?)"`` for the unknown options close to a known one, else ``""``."""
    bare = list(dict.fromkeys(name.partition("=")[0] for name in names))
    found = [(name, closest(name, bare, n=1)) for name in unknown]
    hints = [f"{near[0]!r} for {name!r}" for name, near in found if near]
    return f" (did you mean {', '.join(hints)}?)" if hints else ""


def reference_keyword_problem(options: dict[str, Any], what: str) -> str | None:
    """Why ``reference=<word>`` cannot apply to ``what`` (a source that is not a CARMEN log), or None.

    Every source takes ``reference=FILE``; only a CARMEN log reads a word
    there (which of its lines hold the reference poses). Such a word used to
    reach the other loaders and be refused as an unknown option by a message
    that listed ``reference`` among the options every source takes.
    """
    value = options.get("reference")
    if value is None or str(value) not in REFERENCE_KEYWORDS:
        return None
    return (
        f"reference={value} is a CARMEN log's keyword ({', '.join(REFERENCE_KEYWORDS)}: which of its lines hold "
        f"the reference poses); for {what} reference= names a trajectory file (TUM, KITTI or a corrected CARMEN log)"
    )


@runtime_checkable
class SequenceLoader(Protocol):
    """Reads one file format into a Sequence."""

    format_name: ClassVar[str]
    suffixes: ClassVar[tuple[str, ...]]

    def sniff(self, path: Path) -> bool:
        """True if the file looks like this format (reads at most a few KiB)."""
        ...

    def load(self, path: Path, **options: Any) -> Sequence:
        """The file as a streamed Sequence; format-specific ``options`` (topics, ...)."""
        ...


@runtime_checkable
class SequenceWriter(Protocol):
    """Writes a Sequence in one file format (``albot1 convert``)."""

    format_name: ClassVar[str]

    def write(self, sequence: Sequence, path: Path) -> None:
        """Write every frame (scan, odometry, reference when present) to ``path``."""
        ...


def reference_presence_problem(
    first: Frame, frame: Frame, reader: str, why: str = "it interpolates them to each scan's time"
) -> str | None:
    """Why ``frame`` cannot follow ``first`` in a format that keeps reference poses for all scans or none.

    CARMEN (TRUEPOS lines) and bags (a reference topic) interpolate the
    reference poses to every scan's time, so a sequence where only some frames
    have one would come back with invented poses (or be refused): the writers
    refuse it instead. The albot log stores a reference per view, but its reader
    refuses a log where only some views have one (a run would score none of them),
    so its writer refuses that too, with ``why`` saying so.
    """
    if (first.reference is None) == (frame.reference is None):
        return None
    has, lacks = (frame, first) if frame.reference is not None else (first, frame)
    return (
        f"frame {has.index} has a reference pose but frame {lacks.index} has none; {reader} holds reference "
        f"poses for every scan or for none ({why})"
    )


#: Largest step back (s) of a log's timestamps: CARMEN's ``time_tolerance`` default, and how far a bag's odometry
#: and reference stamps may go back (they are sorted within it). The Intel log's stamps jitter back by up to
#: 0.9 s; a larger step is a clock jump or a second publisher, whose poses sorted among the others would be
#: interpolated into the scans between them.
DEFAULT_TIME_TOLERANCE_S = 1.0


#: Largest time (s) between the two pose samples (odometry or reference) a scan's pose is interpolated between,
#: the loaders' option ``max_pose_gap``. Across a longer gap the robot may have moved any way while nothing was
#: recorded, so the interpolated pose would be invented, not measured. Chosen above the largest such gap of
#: every registered log read with interpolated odometry (``odometry=odom``: intel 3.11 s, aces 2.95 s, fr079
#: 0.24 s; docs/formats.md); bags written by ``albot1 convert`` stamp a pose at every scan, so never interpolate.
DEFAULT_MAX_POSE_GAP_S = 5.0


def max_pose_gap(value: Any, source: object) -> float:
    """The ``max_pose_gap`` option as seconds > 0 (``inf``: no limit); None means the default."""
    if value is None:
        return DEFAULT_MAX_POSE_GAP_S
    try:
        seconds = float(value)
    except (TypeError, ValueError):
        seconds = math.nan
    if not seconds > 0:
        raise DataError(f"{source}: max_pose_gap={value!r}; expected seconds > 0 (or inf for no limit)")
    return seconds


def pose_gap_problem(t: float, before: float, after: float, limit: float, what: str) -> str | None:
    """Why a pose at ``t`` interpolated between samples at ``before`` and ``after`` would be invented, or None."""
    gap = after - before
    if gap <= limit:
        return None
    return (
        f"scan at t = {t:.6f} s falls in a {gap:.3f} s gap of the {what} (samples at {before:.6f} and "
        f"{after:.6f} s); its pose would be interpolated across it, not measured; expected samples at most "
        f"max_pose_gap {limit:g} s apart around every scan (max_pose_gap=inf interpolates across any gap)"
    )
