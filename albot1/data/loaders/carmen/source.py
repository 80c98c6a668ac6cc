"""Bytes of a CARMEN log, decompressed and cut into whole lines, chunk by chunk.

The compression is recognised by its magic bytes (not the file name), so a
renamed ``.clf`` that is really bzip2 still opens. The log is handed out in
chunks of whole lines with their 1-based line numbers, which is what lets the
parser work on many lines at once with numpy while a 100k-scan log is never
decompressed as a whole before the first scan is yielded.

Damaged compressed data (a truncated or corrupt ``.gz``/``.bz2``, see
:mod:`albot1.data.loaders.compressed`) becomes a
:class:`~albot1.data.errors.ParseError` naming the last complete line and the
compressed byte offset, after every complete line before it was handed out.
"""

from __future__ import annotations

from collections.abc import Generator
from dataclasses import dataclass
from pathlib import Path

from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.bz2_parallel import iter_bz2_parallel
from albot1.data.loaders.compressed import DamagedStream, compression_of, iter_decompressed, read_head
from albot1.data.text import without_bom

__all__ = ["CHUNK_BYTES", "LineChunk", "compression_of", "damaged_error", "iter_line_chunks", "read_head"]

#: Decompressed bytes handed to the parser at a time. Large enough that numpy's
#: per-call overhead vanishes, small enough that the first scans come quickly.
CHUNK_BYTES = 1 << 21


@dataclass(frozen=True, slots=True)
class LineChunk:
    """Whole lines ``first_line, first_line + 1, ...`` (1-based, newline stripped)."""

    first_line: int
    lines: list[bytes]


def damaged_error(path: Path, damage: DamagedStream, complete_lines: int) -> ParseError:
    """The ParseError of damaged compressed data after ``complete_lines`` good lines."""
    if complete_lines == 0:
        return ParseError(path, damage.describe(" before its first line could be decompressed"))
    return ParseError(path, damage.describe(" after this line (the last complete one)"), line=complete_lines)


def iter_line_chunks(
    path: Path, *, chunk_bytes: int = CHUNK_BYTES, parallel_bz2: bool = True
) -> Generator[LineChunk, None, None]:
    """The log's lines in chunks; a final line without newline is included.

    ``parallel_bz2`` decompresses the independent blocks of a bzip2 file on
    worker threads (see :mod:`albot1.data.loaders.carmen.bz2_parallel`); the result
    is byte-identical to sequential decompression.
    """
    compression = compression_of(path)
    if compression == "bzip2" and parallel_bz2:
        blocks = iter_bz2_parallel(path)
    else:
        blocks = iter_decompressed(path, compression)
    blocks = without_bom(blocks)  # a leading byte-order mark is no part of the first line
    next_line = 1
    carry = b""
    pending: list[bytes] = []
    pending_size = 0
    while True:
        try:
            block = next(blocks, None)
        except DamagedStream as damage:
            data = carry + b"".join(pending)
            lines = data.split(b"\n")[:-1]  # the last piece is the cut-off line
            if lines:
                yield LineChunk(next_line, lines)
                next_line += len(lines)
            raise damaged_error(path, damage, next_line - 1) from None
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
