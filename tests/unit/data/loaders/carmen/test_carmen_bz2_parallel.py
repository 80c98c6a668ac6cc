"""Block-parallel bzip2 decompression is byte-identical to the sequential decoder."""

from __future__ import annotations

import bz2
from pathlib import Path

import numpy as np
import pytest

from albot1.data.loaders.carmen.bz2_parallel import BLOCK_MAGIC, _block_streams, find_bit_pattern, iter_bz2_parallel
from albot1.data.loaders.compressed import DamagedStream


def sample(seed: int = 3) -> bytes:
    rng = np.random.default_rng(seed)
    words = rng.integers(0, 10_000, size=120_000)
    return ("\n".join(" ".join(map(str, words[i : i + 12])) for i in range(0, len(words), 12)) + "\n").encode()


def test_bit_pattern_found_at_every_shift() -> None:
    for shift in range(8):
        value = (0b1 << (48 + 16 + shift)) | (BLOCK_MAGIC << (16 + shift))
        data = value.to_bytes(16, "big")
        assert find_bit_pattern(data, BLOCK_MAGIC) == [128 - 16 - shift - 48]


@pytest.mark.parametrize("level", [1, 9])
def test_parallel_equals_sequential(tmp_path: Path, level: int) -> None:
    raw = sample()
    path = tmp_path / "x.bz2"
    path.write_bytes(bz2.compress(raw, compresslevel=level) + bz2.compress(b"second stream\n"))
    streams = _block_streams(path.read_bytes())
    assert streams is not None and len(streams) >= (2 if level == 1 else 1) + 1
    assert b"".join(iter_bz2_parallel(path, workers=2)) == raw + b"second stream\n"


def test_corrupt_block_falls_back_to_the_sequential_error(tmp_path: Path) -> None:
    data = bytearray(bz2.compress(sample(), compresslevel=1))
    data[len(data) * 3 // 4] ^= 0x55
    path = tmp_path / "c.bz2"
    path.write_bytes(bytes(data))
    with pytest.raises(DamagedStream, match="corrupt"):
        b"".join(iter_bz2_parallel(path, workers=2))
