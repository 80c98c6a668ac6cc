"""Files no loader recognises: one specific sentence (empty, comments only, a folder, damaged compressed
data, binary data, or the first line shown as found) instead of "not a recognised log"."""

from __future__ import annotations

import bz2
import gzip
from pathlib import Path

import pytest

from albot1.data.errors import DataError, ParseError, UnknownFormatError
from albot1.data.loaders.registry import load, loader_for

FLASER = "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 {t} host {t}"
LOG = ("\n".join(FLASER.format(t=k) for k in range(3000)) + "\n").encode()


def write(tmp_path: Path, name: str, data: bytes | str) -> Path:
    path = tmp_path / name
    path.write_bytes(data.encode() if isinstance(data, str) else data)
    return path


@pytest.mark.parametrize(
    ("name", "data", "error", "message"),
    [
        ("empty.clf", b"", UnknownFormatError, r"empty\.clf: the file is empty \(0 bytes\); expected a CARMEN log"),
        ("c.clf", "# one\n\n# two\n", UnknownFormatError, r"c\.clf: the file holds only comments and blank lines \(3"),
        (
            "c.clf.gz",
            gzip.compress(b"# one\n", mtime=0),
            UnknownFormatError,
            r"gzip-compressed file holds only comments",
        ),
        ("z.gz", gzip.compress(b"", mtime=0), UnknownFormatError, r"z\.gz: the gzip-compressed file holds no data"),
        ("b.bin", b"\x00\x01\x02binary\xff" * 20, UnknownFormatError, r"b\.bin: binary data of no known format"),
        (
            "w.clf",
            (FLASER.format(t=0) + "\n").encode("utf-16"),
            UnknownFormatError,
            r"w\.clf: UTF-16 text \(its byte-order mark says so\); the logs are read as UTF-8 or ASCII text: "
            r"convert it first \(e\.g\. iconv -f UTF-16 -t UTF-8\)",
        ),
        ("w4.clf", (FLASER.format(t=0) + "\n").encode("utf-32"), UnknownFormatError, r"w4\.clf: UTF-32 text"),
        (
            "bom.clf",
            b"\xef\xbb\xbf",
            UnknownFormatError,
            r"bom\.clf: the file holds no data, only a UTF-8 byte-order mark; expected a CARMEN log",
        ),
        (
            "t.txt",
            "# header\nhello world\n",
            ParseError,
            r"t\.txt:2: the first line that is not a comment \(text, 11 characters\) begins no known format",
        ),
        (
            "s.clf",
            "flaser 3 1 2 3\n",
            ParseError,
            r"s\.clf:1: the first line that is not a comment \(text, 14 characters\) begins no known format",
        ),
    ],
)
def test_unrecognised_files_say_what_they_are(
    tmp_path: Path, name: str, data: bytes | str, error: type[DataError], message: str
) -> None:
    with pytest.raises(error, match=message):
        loader_for(write(tmp_path, name, data))


def test_a_plain_folder(tmp_path: Path) -> None:
    (tmp_path / "f").mkdir()
    with pytest.raises(UnknownFormatError, match=r"f: a folder without metadata\.yaml, not a ROS2 bag"):
        loader_for(tmp_path / "f")


def test_truncated_single_block_bzip2_says_truncated_not_unrecognised(tmp_path: Path) -> None:
    data = bz2.compress(LOG[:4000])
    path = write(tmp_path, "t.clf.bz2", data[: len(data) // 2])
    with pytest.raises(
        ParseError, match=rf"t\.clf\.bz2: the bzip2 data is truncated before its first line .* byte {len(data) // 2}"
    ):
        load(path)


def test_corrupt_single_block_bzip2_says_corrupt_and_names_the_block(tmp_path: Path) -> None:
    data = bytearray(bz2.compress(LOG[:4000]))
    data[len(data) // 2] ^= 0xFF
    with pytest.raises(ParseError, match=r"the bzip2 data is corrupt .* bzip2 block that starts at compressed byte 4 "):
        load(write(tmp_path, "c.clf.bz2", bytes(data)))


def test_tiny_truncated_gzip_names_the_last_complete_line(tmp_path: Path) -> None:
    data = gzip.compress(b"# CARMEN\n" + LOG[:300])
    for cut in (12, 40):  # the header alone, then a little more: whatever decodes is used
        path = write(tmp_path, f"t{cut}.clf.gz", data[:cut])
        with pytest.raises(ParseError, match=r"the gzip data is truncated"):
            list(load(path).frames())


def test_truncated_gzip_after_hundreds_of_lines_names_the_last_one(tmp_path: Path) -> None:
    data = gzip.compress(LOG)
    path = write(tmp_path, "t.clf.gz", data[: len(data) // 2])
    with pytest.raises(ParseError) as info:
        list(load(path).frames())
    assert info.value.line is not None and info.value.line > 500
    assert "the gzip data is truncated after this line (the last complete one)" in str(info.value)
