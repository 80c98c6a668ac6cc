"""Damaged gzip/bzip2 data: every byte before the damage is handed out, and the damage says what and where."""

from __future__ import annotations

import bz2
import gzip
from pathlib import Path

import pytest

from albot1.data.loaders.compressed import DamagedStream, iter_decompressed, iter_lines, read_head

TEXT = b"".join(b"line %05d of a log with some numbers 1.25 2.5 3.75\n" % k for k in range(20000))


def write(tmp_path: Path, name: str, data: bytes) -> Path:
    path = tmp_path / name
    path.write_bytes(data)
    return path


def decoded_until_damage(path: Path) -> tuple[bytes, DamagedStream | None]:
    out = b""
    try:
        for block in iter_decompressed(path):
            out += block
    except DamagedStream as damage:
        return out, damage
    return out, None


@pytest.mark.parametrize("codec", [gzip, bz2])
def test_intact_single_and_concatenated_streams(tmp_path: Path, codec) -> None:  # type: ignore[no-untyped-def]
    one = write(tmp_path, "one", codec.compress(TEXT))
    two = write(tmp_path, "two", codec.compress(TEXT[:1000]) + codec.compress(TEXT[1000:]))
    padded = write(tmp_path, "pad", codec.compress(TEXT) + b"\0" * 700)  # tape-block padding, as gzip tolerates
    for path in (one, two, padded):
        assert decoded_until_damage(path) == (TEXT, None)
    assert list(iter_lines(one)) == TEXT.split(b"\n")[:-1]


def test_truncated_gzip_keeps_every_byte_before_the_cut(tmp_path: Path) -> None:
    data = gzip.compress(TEXT)
    path = write(tmp_path, "t.gz", data[: len(data) // 2])
    out, damage = decoded_until_damage(path)
    assert damage is not None and damage.kind == "truncated"
    assert len(out) > len(TEXT) // 3 and TEXT.startswith(out)
    assert f"the file ends at byte {len(data) // 2} inside the compressed stream" in damage.describe()


def test_corrupt_gzip_is_located_and_earlier_pieces_are_kept(tmp_path: Path) -> None:
    data = bytearray(gzip.compress(TEXT))
    data[len(data) * 3 // 4] ^= 0xFF
    out, damage = decoded_until_damage(write(tmp_path, "c.gz", bytes(data)))
    assert damage is not None and damage.kind == "corrupt"
    assert TEXT.startswith(out[: len(out) // 2]) and len(out) > len(TEXT) // 2
    assert "the decompressor rejects compressed byte" in damage.describe()


def test_trailing_garbage_after_a_gzip_stream(tmp_path: Path) -> None:
    data = gzip.compress(TEXT) + b"GARBAGE"
    out, damage = decoded_until_damage(write(tmp_path, "g.gz", data))
    assert out == TEXT and damage is not None
    assert f"7 unexpected bytes follow the end of the data at byte {len(data) - 7}" in damage.describe()


def test_corrupt_bzip2_names_its_block(tmp_path: Path) -> None:
    data = bytearray(bz2.compress(TEXT, compresslevel=1))  # 100 kB blocks: several of them
    data[len(data) // 2] ^= 0x55
    out, damage = decoded_until_damage(write(tmp_path, "c.bz2", bytes(data)))
    assert damage is not None and damage.kind == "corrupt"
    assert "the decompressor rejects the bzip2 block that starts at compressed byte" in damage.describe()
    assert 0 < len(out) < len(TEXT) and TEXT.startswith(out)


def test_truncated_single_block_bzip2_gives_nothing_and_says_truncated(tmp_path: Path) -> None:
    data = bz2.compress(TEXT[:5000])
    out, damage = decoded_until_damage(write(tmp_path, "t.bz2", data[:-30]))
    assert out == b"" and damage is not None and damage.kind == "truncated"


def test_read_head_returns_what_could_be_decoded(tmp_path: Path) -> None:
    data = gzip.compress(TEXT)
    assert read_head(write(tmp_path, "t.gz", data[: len(data) // 2]), 100) == TEXT[:100]
    assert read_head(write(tmp_path, "x.bz2", bz2.compress(TEXT)[:50]), 100) == b""
    assert read_head(write(tmp_path, "plain", TEXT[:10]), 100) == TEXT[:10]
