"""Bad CARMEN input: one ParseError naming file:line and what was expected."""

from __future__ import annotations

import bz2
import gzip
from pathlib import Path

import pytest

from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.loader import CarmenLoader

GOOD = "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 {t} host {t}"


def run(tmp_path: Path, text: str | bytes, name: str = "bad.clf", **options: object) -> None:
    path = tmp_path / name
    path.write_bytes(text.encode() if isinstance(text, str) else text)
    for _ in CarmenLoader().load(path, **options).frames():
        pass


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("FLASER 3 1.0 2.0 0 0 0 0 0 0 1.0 host 1.0", r"bad\.clf:2: FLASER has 12 fields after the name, expected 13"),
        ("FLASER 3 1.0 x 3.0 0 0 0 0 0 0 1.0 host 1.0", r"bad\.clf:2: FLASER field 3 is 'x', expected a number"),
        ("FLASER 3 1.0 nan 3.0 0 0 0 0 0 0 1.0 host 1.0", r"bad\.clf:2: FLASER range 2 is nan, expected a finite"),
        ("FLASER 3 1.0 -2.0 3.0 0 0 0 0 0 0 1.0 host 1.0", r"bad\.clf:2: FLASER range 2 is -2\.0, expected a finite"),
        ("FLASER three 1.0", r"bad\.clf:2: FLASER beam count is 'three', expected a non-negative integer"),
        ("FLASER 3 1.0 2.0 3.0 0 0 inf 0 0 0 1.0 host 1.0", r"bad\.clf:2: FLASER pose/timestamp fields contain inf"),
        ("PARAM lonely", r"bad\.clf:2: PARAM needs a name and a value"),
        ("flaser 3 1 2 3", r"bad\.clf:2: expected a CARMEN message name"),
        ("\x00\x01garbage", r"bad\.clf:2: expected a CARMEN message name"),
    ],
)
def test_bad_lines_name_file_line_and_expectation(tmp_path: Path, line: str, message: str) -> None:
    with pytest.raises(ParseError, match=message):
        run(tmp_path, GOOD.format(t=0.5) + "\n" + line + "\n")


def test_bad_odom_line_when_odom_is_used(tmp_path: Path) -> None:
    text = GOOD.format(t=0.5) + "\nODOM 1 2 host\n"
    with pytest.raises(ParseError, match=r"bad\.clf:2: ODOM has 3 fields after the name, expected 9"):
        run(tmp_path, text, odometry="odom")
    run(tmp_path, text)  # laser-pose odometry: ODOM lines are not decoded at all


def test_robotlaser1_with_too_few_fields(tmp_path: Path) -> None:
    line = "ROBOTLASER1 0 -1 2 1 20 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0 1.0 host"
    with pytest.raises(ParseError, match=r"bad\.clf:1: ROBOTLASER1 has 25 fields after the name, expected 26"):
        run(tmp_path, line + "\n")


def test_empty_file(tmp_path: Path) -> None:
    with pytest.raises(ParseError, match=r"empty\.clf: the file is empty"):
        run(tmp_path, "", "empty.clf")


def test_comments_only_means_no_scans(tmp_path: Path) -> None:
    with pytest.raises(ParseError, match=r"c\.clf:1: no scans in the first 2 MiB"):
        run(tmp_path, "# nothing\n# here\nODOM 0 0 0 0 0 0 1 host 1\n", "c.clf")


def test_truncated_gzip(tmp_path: Path) -> None:
    data = gzip.compress(("\n".join(GOOD.format(t=k) for k in range(2000)) + "\n").encode())
    with pytest.raises(ParseError, match=r"t\.clf\.gz:\d+: the gzip data is truncated or corrupt"):
        run(tmp_path, data[: len(data) // 2], "t.clf.gz")


@pytest.mark.parametrize("parallel", [True, False])
def test_truncated_bzip2(tmp_path: Path, parallel: bool) -> None:
    data = bz2.compress(("\n".join(GOOD.format(t=k) for k in range(2000)) + "\n").encode())
    path = tmp_path / "t.clf.bz2"
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(ParseError, match=r"t\.clf\.bz2:\d+: the bzip2 data is truncated or corrupt"):
        for _ in CarmenLoader().load(path, parallel_bz2=parallel).frames():
            pass


def test_corrupt_bzip2(tmp_path: Path) -> None:
    data = bytearray(bz2.compress(("\n".join(GOOD.format(t=k) for k in range(2000)) + "\n").encode()))
    data[len(data) // 2] ^= 0xFF
    with pytest.raises(ParseError, match=r"c\.clf\.bz2:\d+: the bzip2 data is truncated or corrupt"):
        run(tmp_path, bytes(data), "c.clf.bz2")
