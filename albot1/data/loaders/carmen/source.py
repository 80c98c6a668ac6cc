"""Bytes of a CARMEN log, decompressed and cut into whole lines, chunk by chunk.

The compression is recognised by its magic bytes (not the file name), so a
renamed ``.clf`` that is really bzip2 still opens. The log is handed out in
chunks of whole lines with their 1-based line numbers, which is what lets the
parser work on many lines at once with numpy while a 100k-scan log is never
decompressed as a whole before the first scan is yielded.

Decompression failures (truncated or corrupt ``.gz``/``.bz2``) become a
:class:`~albot1.data.errors.ParseError` naming the last complete line, instead
of the ``EOFError``/``OSError``/``zlib.error`` the codecs raise.
"""

from __future__ import annotations

import bz2
import gzip
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.bz2_parallel import iter_bz2_parallel

GZIP_MAGIC = b"\x1f\x8b"
BZ2_MAGIC = b"BZh"

#: Decompressed bytes handed to the parser at a time. Large enough that numpy's
#: per-call overhead vanishes, small enough that the first scans come quickly.
CHUNK_BYTES = 1 << 21


@dataclass(frozen=True, slots=True)
class LineChunk:
    """Whole lines ``first_line, first_line + 1, ...`` (1-based, newline stripped)."""

    first_line: int
    lines: list[bytes]


def compression_of(path: Path) -> str:
    """``"gzip"``, ``"bzip2"`` or ``"none"``, from the first bytes of the file."""
    with path.open("rb") as fh:
        head = fh.read(3)
    if head.startswith(GZIP_MAGIC):
        return "gzip"
    if head.startswith(BZ2_MAGIC):
        return "bzip2"
    return "none"


def _open(path: Path, compression: str) -> BinaryIO:
    if compression == "gzip":
        return gzip.open(path, "rb")  # type: ignore[return-value]
    if compression == "bzip2":
        return bz2.open(path, "rb")  # type: ignore[return-value]
    return path.open("rb")


def read_head(path: Path, size: int = 4096) -> bytes:
    """The first ``size`` decompressed bytes (for sniffing); empty on any decoding problem."""
    try:
        with _open(path, compression_of(path)) as fh:
            return fh.read(size)
    except (OSError, EOFError, zlib.error):
        return b""


def _raw_blocks(path: Path, compression: str, chunk_bytes: int, parallel: bool) -> Iterator[bytes]:
    if compression == "bzip2" and parallel:
        yield from iter_bz2_parallel(path)
        return
    with _open(path, compression) as fh:
        while True:
            block = fh.read(chunk_bytes)
            if not block:
                return
            yield block


def iter_line_chunks(path: Path, *, chunk_bytes: int = CHUNK_BYTES, parallel_bz2: bool = True) -> Iterator[LineChunk]:
    """The log's lines in chunks; a final line without newline is included.

    ``parallel_bz2`` decompresses the independent blocks of a bzip2 file on
    worker threads (see :mod:`albot1.data.loaders.carmen.bz2_parallel`); the result
    is byte-identical to sequential decompression.
    """
    compression = compression_of(path)
    next_line = 1
    carry = b""
    blocks = _raw_blocks(path, compression, chunk_bytes, parallel_bz2)
    pending: list[bytes] = []
    pending_size = 0
    while True:
        try:
            block = next(blocks, None)
        except (OSError, EOFError, zlib.error, ValueError) as exc:
            raise ParseError(
                path,
                f"the {compression} data is truncated or corrupt after this line ({exc}); "
                f"expected a complete {compression} stream",
                line=max(next_line - 1, 1),
            ) from None
        if block is not None:
            pending.append(block)
            pending_size += len(block)
            if pending_size < chunk_bytes:
                continue
        data = carry + b"".join(pending)
        pending, pending_size = [], 0
        if block is None:
            lines = data.split(b"\n")
            if lines and lines[-1] == b"":
                lines.pop()
            carry = b""
        else:
            cut = data.rfind(b"\n")
            if cut < 0:
                carry = data
                continue
            lines = data[:cut].split(b"\n")
            carry = data[cut + 1 :]
        if lines:
            yield LineChunk(next_line, lines)
            next_line += len(lines)
        if block is None:
            return
