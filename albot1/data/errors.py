"""Errors of the data layer: every message says where (file:line or message
index) and what was expected, so that a user can fix the input."""

from __future__ import annotations

from pathlib import Path

from albot1.errors import Albot1Error


class DataError(Albot1Error):
    """Base class of data-layer errors (loading, parsing, converting, fetching)."""


class ParseError(DataError):
    """A file's content is not what its format requires.

    ``location`` is a 1-based line number for text formats or a 0-based
    message index for bags; it is rendered as ``file:line`` / ``file[#i]``.
    """

    def __init__(self, path: str | Path, message: str, *, line: int | None = None, index: int | None = None) -> None:
        self.path = str(path)
        self.line = line
        self.index = index
        where = self.path
        if line is not None:
            where = f"{where}:{line}"
        elif index is not None:
            where = f"{where}[message #{index}]"
        super().__init__(f"{where}: {message}")


class UnknownFormatError(DataError):
    """No loader recognises a file, or an unknown format name was asked for."""


class DatasetNotFoundError(DataError):
    """A dataset name is not registered, or its files are not available locally."""


class TopicError(DataError):
    """A bag topic is missing or ambiguous; the message lists the bag's topics."""


class FetchError(DataError):
    """A download failed or its checksum did not match."""


class ChecksumError(DataError):
    """A data file is not the one its manifest's sha256 names (a wrong or damaged copy)."""


class ReferenceOptionError(DataError):
    """A dataset reference option (``odometry=reference``, ``views=D_M:A_DEG``) cannot be applied."""


class WriteError(DataError):
    """An output cannot be written: it exists, its folder is missing, not a folder or not writable,
    the file system is read-only or full. The message names the path."""


class SliceError(DataError):
    """A slice of a dataset reference (``NAME[:STOP:STEP]``) or a scan limit is not a positive count."""


class UnwritableError(DataError):
    """A sequence holds what the target format's reader would refuse, so the writer does not write it
    (the message names the output and the frame)."""
