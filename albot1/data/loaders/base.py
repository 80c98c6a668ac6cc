"""The explicit protocols every file-format loader and writer implements.

The registry asks a loader ``sniff(path)`` (a cheap look at the file's
signature) instead of probing attributes; ``load`` returns a streamed
:class:`~albot1.data.model.Sequence` and raises only
:class:`~albot1.data.errors.DataError` subclasses.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar, Protocol, runtime_checkable

from albot1.data.model import Frame, Sequence

#: The options every source takes besides its loader's own (applied by :mod:`albot1.data.open` and
#: :mod:`albot1.data.attach`, not by a loader): loaders name them in their unknown-option errors.
COMMON_OPTIONS = ("relations", "reference", "reference_max_dt", "odometry=reference", "views")


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
