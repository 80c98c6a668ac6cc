"""Decompressing a log while keeping track of where the compressed data breaks.

Why not ``gzip.open``/``bz2.open``: they decode in blocks and raise one bare
``EOFError``/``OSError`` that loses everything decoded in the failing read,
so a truncated log used to be reported at "line 1" although hundreds of
lines were fine, and a corrupt one as "not a recognised log". Here the
compressed file is fed to ``zlib``/``bz2`` decompressors piece by piece:
every decoded byte is handed on before a failure, and the failure
(:class:`DamagedStream`) says whether the data is *truncated* (the file ends
inside the compressed stream) or *corrupt* (the codec rejects it), and at
which compressed byte offset. The line readers (CARMEN, albot log) turn it
into a :class:`~albot1.data.errors.ParseError` naming the last complete line.

Concatenated streams (``cat a.gz b.gz``, pbzip2 output) are read in full, as
``gzip``/``bz2`` do; zero padding after the last stream is ignored, any other
trailing bytes are reported as corrupt. The compression is recognised by its
magic bytes, not by the file name.
"""

from __future__ import annotations

import bz2
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import Protocol

from albot1.data.text import without_bom

GZIP_MAGIC = b"\x1f\x8b"
BZ2_MAGIC = b"BZh"
#: bzip2 marks each block and the end of a stream with these 48-bit patterns, at any *bit* offset.
BZ2_BLOCK_MAGIC = 0x314159265359
BZ2_END_MAGIC = 0x177245385090
_BZ2_MAGIC_BITS = 48
#: Compressed bytes fed to the decompressor at a time. A failing call loses its own output, so the
#: pieces are small: the lines decoded before a damaged spot still count, and a gzip failure is
#: located to within 8 KiB (bzip2 checks whole blocks of up to 900 kB; its block is named instead).
PIECE_BYTES = 1 << 13
#: Uncompressed files are read this much at a time.
PLAIN_BYTES = 1 << 21


class DamagedStream(Exception):
    """The compressed data ends early (``kind="truncated"``) or is rejected (``kind="corrupt"``).

    ``where`` locates the damage in the compressed file in words. Internal to
    the data layer: every reader catches it and raises a ParseError with the
    line information only it knows.
    """

    def __init__(self, compression: str, kind: str, where: str, reason: str) -> None:
        self.compression = compression
        self.kind = kind
        self.where = where
        self.reason = reason
        super().__init__(self.describe())

    def describe(self, after: str = "") -> str:
        """One line: what is wrong, where in the compressed file, what was expected.

        ``after`` places it among the decoded lines (e.g. ``" after this line (the last complete one)"``).
        """
        c = self.compression
        if self.kind == "truncated":
            return (
                f"the {c} data is truncated{after}: {self.where} (an interrupted download or copy?); "
                f"expected a complete {c} stream"
            )
        return f"the {c} data is corrupt{after}: {self.where} ({self.reason}); expected a valid {c} stream"


class _Decompressor(Protocol):
    eof: bool
    unused_data: bytes

    def decompress(self, data: bytes) -> bytes: ...


def find_bit_pattern(data: bytes, pattern: int) -> list[int]:
    """Sorted bit offsets (MSB-first) at which the 48-bit ``pattern`` occurs in ``data``."""
    found: set[int] = set()
    for shift in range(8):
        window = (pattern << (8 - shift)).to_bytes(7, "big")
        needle = window[1:6]  # the five bytes fully covered by the pattern at this shift
        start = 0
        while True:
            idx = data.find(needle, start)
            if idx < 0:
                break
            start = idx + 1
            bit = (idx - 1) * 8 + shift
            if bit < 0 or (bit + _BZ2_MAGIC_BITS + 7) // 8 > len(data):
                continue
            first = bit // 8
            chunk = int.from_bytes(data[first : first + 7].ljust(7, b"\0"), "big")
            if (chunk >> (56 - _BZ2_MAGIC_BITS - bit % 8)) & ((1 << _BZ2_MAGIC_BITS) - 1) == pattern:
                found.add(bit)
    return sorted(found)


def _bz2_block_at(path: Path, offset: int) -> str:
    """Which bzip2 block holds compressed byte ``offset`` (the decoder only checks a block at its end)."""
    starts = [bit // 8 for bit in find_bit_pattern(path.read_bytes(), BZ2_BLOCK_MAGIC)]
    before = [i for i, start in enumerate(starts) if start < offset]
    if not before:
        return f"the decompressor rejects compressed byte {offset} or one before it"
    k = before[-1]
    return (
        f"the decompressor rejects the bzip2 block that starts at compressed byte {starts[k]} "
        f"(block {k + 1} of the {len(starts)} found in the file)"
    )


def compression_of(path: Path) -> str:
    """``"gzip"``, ``"bzip2"`` or ``"none"``, from the first bytes of the file."""
    with path.open("rb") as fh:
        head = fh.read(3)
    if head.startswith(GZIP_MAGIC):
        return "gzip"
    if head.startswith(BZ2_MAGIC):
        return "bzip2"
    return "none"


def _new(compression: str) -> _Decompressor:
    if compression == "gzip":
        return zlib.decompressobj(wbits=31)  # type: ignore[return-value]
    return bz2.BZ2Decompressor()  # type: ignore[return-value]


def iter_decompressed(path: Path, compression: str | None = None) -> Iterator[bytes]:
    """The decompressed bytes of ``path`` in pieces; :class:`DamagedStream` where the data breaks.

    Every byte decoded before the failure is yielded first, so a reader can
    count the complete lines it received.
    """
    compression = compression or compression_of(path)
    with path.open("rb") as fh:
        if compression == "none":
            while block := fh.read(PLAIN_BYTES):
                yield block
            return
        size = path.stat().st_size
        decoder = _new(compression)
        fed = False  # whether the current stream has received bytes
        streams = 0  # streams completed
        offset = 0  # compressed bytes before the current piece
        while piece := fh.read(PIECE_BYTES):
            pos = 0
            while pos < len(piece):
                data = piece[pos:] if pos else piece
                if streams and not fed:  # between streams: skip zero padding, as gzip does
                    stripped = data.lstrip(b"\0")
                    pos += len(data) - len(stripped)
                    data = stripped
                    if not data:
                        break
                try:
                    out = decoder.decompress(data)
                except (OSError, EOFError, ValueError, zlib.error) as exc:
                    reason = str(exc) or type(exc).__name__
                    if streams and not fed:
                        at = offset + pos
                        where = f"{size - at} unexpected bytes follow the end of the data at byte {at} of {size}"
                    elif compression == "bzip2":
                        where = _bz2_block_at(path, offset + len(piece))
                    else:
                        where = f"the decompressor rejects compressed byte {offset + len(piece)} or one before it"
                    raise DamagedStream(compression, "corrupt", f"{where} (file size {size} bytes)", reason) from None
                fed = True
                if out:
                    yield out
                if not decoder.eof:
                    break  # the whole piece was taken in
                rest = decoder.unused_data
                pos += len(data) - len(rest)
                decoder, fed, streams = _new(compression), False, streams + 1
            offset += len(piece)
        if fed:
            where = f"the file ends at byte {size} inside the compressed stream"
            raise DamagedStream(compression, "truncated", where, "end of file inside the stream")


def read_head(path: Path, size: int = 4096) -> bytes:
    """The first ``size`` decompressed bytes (for sniffing), without a leading byte-order mark
    (:mod:`albot1.data.text`); what could be decoded when the data is damaged."""
    out = b""
    try:
        for block in without_bom(iter_decompressed(path)):
            out += block
            if len(out) >= size:
                break
    except (DamagedStream, OSError):
        pass
    return out[:size]


def iter_lines(path: Path) -> Iterator[bytes]:
    """The decompressed file's lines (newline removed); :class:`DamagedStream` after the last complete one.

    A final line without a newline is yielded when the data is intact, dropped
    (it may be cut off) when it is not. A leading byte-order mark is dropped (:mod:`albot1.data.text`).
    """
    carry = b""
    for block in without_bom(iter_decompressed(path)):
        lines = (carry + block).split(b"\n")
        carry = lines.pop()
        yield from lines
    if carry:
        yield carry
