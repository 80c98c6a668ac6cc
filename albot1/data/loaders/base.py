"""The explicit protocols every file-format loader and writer implements.

The registry asks a loader ``sniff(path)`` (a cheap look at the file's
signature) instead of probing attributes; ``load`` returns a streamed
:class:`~albot1.data.model.Sequence` and raises only
:class:`~albot1.data.errors.DataError` subclasses.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar, Protocol, runtime_checkable

from albot1.data.model import Sequence


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
