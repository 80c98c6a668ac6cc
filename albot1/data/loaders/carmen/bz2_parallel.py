"""bzip2 decompression on several threads, block by block, in order.

Why: decompressing ``intel.clf.bz2`` (2.2 MB -> 16 MB) alone takes about 1 s
on one core, which by itself exceeds the loader's 1 s budget. bzip2 blocks
are compressed independently (this is how ``bzip2recover`` and ``lbzip2``
work), and CPython's ``bz2`` releases the GIL while decompressing, so threads
give real parallelism.

How: every block starts with the 48-bit magic ``0x314159265359`` at an
arbitrary *bit* offset, followed by its 32-bit CRC; a stream ends with
``0x177245385090`` and a combined CRC. Each block is cut out and wrapped into
a one-block stream (``BZh9`` + block bits + end magic + the block's CRC, which
is the combined CRC of a one-block stream); ``bz2`` then checks every CRC.

A 48-bit magic can in principle occur inside compressed data; if a cut block
fails to decompress, the generator falls back to the sequential decoder and
resumes after the bytes already produced, so the output is always identical to
``bz2.open(path).read()`` and genuine damage is reported by the sequential
decoder (:class:`~albot1.data.loaders.compressed.DamagedStream`, with its
offset).
"""

from __future__ import annotations

import bz2
import os
from collections import deque
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

from albot1.data.loaders.compressed import BZ2_BLOCK_MAGIC as BLOCK_MAGIC
from albot1.data.loaders.compressed import BZ2_END_MAGIC as END_MAGIC
from albot1.data.loaders.compressed import find_bit_pattern, iter_decompressed

__all__ = ["BLOCK_MAGIC", "END_MAGIC", "find_bit_pattern", "iter_bz2_parallel"]

_MAGIC_BITS = 48


class _BlockFailed(Exception):
    """A cut-out block did not decompress (corrupt data or a false magic match)."""


def _bits(data: bytes, start: int, stop: int) -> int:
    """Bits ``[start, stop)`` of ``data`` (MSB-first) as an integer (Python ints shift in C, fast)."""
    first, last = start // 8, (stop + 7) // 8
    value = int.from_bytes(data[first:last], "big")
    return (value >> (last * 8 - stop)) & ((1 << (stop - start)) - 1)


def _block_streams(data: bytes) -> list[bytes] | None:
    """One self-contained bzip2 stream per block, or None if the layout is not understood."""
    if not data.startswith(b"BZh"):
        return None
    blocks = find_bit_pattern(data, BLOCK_MAGIC)
    ends = find_bit_pattern(data, END_MAGIC)
    if not blocks or not ends or ends[-1] < blocks[-1]:
        return None  # truncated or unusual: the sequential decoder reports it precisely
    boundaries = sorted(set(blocks) | set(ends))
    streams = []
    for start in blocks:
        stop = boundaries[boundaries.index(start) + 1]
        crc = _bits(data, start + _MAGIC_BITS, start + _MAGIC_BITS + 32)
        nbits = stop - start + _MAGIC_BITS + 32
        value = (_bits(data, start, stop) << (_MAGIC_BITS + 32)) | (END_MAGIC << 32) | crc
        pad = -nbits % 8
        streams.append(b"BZh9" + (value << pad).to_bytes((nbits + pad) // 8, "big"))
    return streams


def _decompress(stream: bytes) -> bytes:
    try:
        return bz2.decompress(stream)
    except (OSError, ValueError, EOFError) as exc:
        raise _BlockFailed(str(exc)) from None


def iter_bz2_parallel(path: Path, workers: int | None = None) -> Iterator[bytes]:
    """Decompressed bytes of ``path`` in file order (a few blocks in flight at a time)."""
    data = path.read_bytes()
    streams = _block_streams(data)
    produced = 0
    if streams is not None and len(streams) > 1:
        n_workers = workers or min(4, os.cpu_count() or 1)
        with ThreadPoolExecutor(max_workers=n_workers, thread_name_prefix="bz2") as pool:
            in_flight: deque[Future[bytes]] = deque()
            todo = iter(streams)
            try:
                for stream in todo:
                    in_flight.append(pool.submit(_decompress, stream))
                    if len(in_flight) >= 2 * n_workers:
                        out = in_flight.popleft().result()
                        produced += len(out)
                        yield out
                while in_flight:
                    out = in_flight.popleft().result()
                    produced += len(out)
                    yield out
                return
            except _BlockFailed:
                for fut in in_flight:
                    fut.cancel()
    skip = produced  # resume the sequential decoder after the bytes already handed out
    for block in iter_decompressed(path, "bzip2"):
        if skip >= len(block):
            skip -= len(block)
            continue
        yield block[skip:] if skip else block
        skip = 0
