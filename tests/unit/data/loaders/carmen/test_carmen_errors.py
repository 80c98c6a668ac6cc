"""Bad CARMEN input: one ParseError naming file:line and what was expected."""

from __future__ import annotations

import bz2
import gzip
import zlib
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


@pytest.mark.parametrize(
    ("token", "shown"),
    [("2_0", "'2_0'"), ("\uff12.0", "'\uff12.0'"), ("\u0662.0", "'\u0662.0'")],
    ids=["digit-grouping", "full-width", "arabic-indic"],
)
def test_a_number_numpy_refuses_is_named_at_its_own_line(tmp_path: Path, token: str, shown: str) -> None:
    """``float()`` takes ``2_0``; numpy's bulk conversion does not. The error names the true line and token,
    not the first line of the group (line 1), which used to be reported."""
    lines = [GOOD.format(t=k) for k in range(6)]
    lines[4] = lines[4].replace(" 2.0 ", f" {token} ", 1)
    with pytest.raises(ParseError, match=rf"bad\.clf:5: FLASER field 3 is {shown}, expected a number \(n r1"):
        run(tmp_path, "\n".join(lines) + "\n")


def test_a_line_numpy_alone_refuses_is_named(tmp_path: Path) -> None:
    """A carriage return between two fields splits into the right count of numbers, yet numpy refuses the
    line: the error still names that line (each line converted alone), not the group's first."""
    lines = [GOOD.format(t=k) for k in range(6)]
    lines[3] = lines[3].replace(" 2.0 ", " 2.0\r", 1)
    with pytest.raises(ParseError, match=r"bad\.clf:4: FLASER line could not be read as numbers \(.*\); expected n r1"):
        run(tmp_path, "\n".join(lines) + "\n")


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


def test_no_scans_only_odometry(tmp_path: Path) -> None:
    with pytest.raises(ParseError, match=r"c\.clf:1: no front-laser scans in the first 2 MiB"):
        run(tmp_path, "# nothing\n# here\nODOM 0 0 0 0 0 0 1 host 1\n", "c.clf")


def test_comments_only_says_so(tmp_path: Path) -> None:
    with pytest.raises(ParseError, match=r"c\.clf:3: the log holds only comments and blank lines \(3 lines\)"):
        run(tmp_path, "# nothing\n\n# here\n", "c.clf")


def test_truncated_gzip_names_the_last_complete_line(tmp_path: Path) -> None:
    text = "\n".join(GOOD.format(t=k) for k in range(2000)) + "\n"
    data = gzip.compress(text.encode())
    cut = data[: len(data) // 2]
    # what zlib can decode from the cut stream: its complete lines are the ones the error must name
    decoded = zlib.decompressobj(wbits=31).decompress(cut)
    last = decoded.count(b"\n")
    assert last > 100
    with pytest.raises(ParseError, match=rf"t\.clf\.gz:{last}: the gzip data is truncated after this line"):
        run(tmp_path, cut, "t.clf.gz")


@pytest.mark.parametrize("parallel", [True, False])
def test_truncated_single_block_bzip2(tmp_path: Path, parallel: bool) -> None:
    data = bz2.compress(("\n".join(GOOD.format(t=k) for k in range(2000)) + "\n").encode())
    path = tmp_path / "t.clf.bz2"
    path.write_bytes(data[: len(data) // 2])
    message = rf"t\.clf\.bz2: the bzip2 data is truncated before its first line .*ends at byte {len(data) // 2} "
    with pytest.raises(ParseError, match=message):
        for _ in CarmenLoader().load(path, parallel_bz2=parallel).frames():
            pass


@pytest.mark.parametrize("parallel", [True, False])
def test_truncated_multi_block_bzip2_names_the_last_good_line(tmp_path: Path, parallel: bool) -> None:
    first = ("\n".join(GOOD.format(t=k) for k in range(3000)) + "\n").encode()
    second = ("\n".join(GOOD.format(t=3000 + k) for k in range(3000)) + "\n").encode()
    data = bz2.compress(first) + bz2.compress(second)  # two streams, as pbzip2 writes
    path = tmp_path / "m.clf.bz2"
    path.write_bytes(data[: len(data) - 200])
    with pytest.raises(ParseError, match=r"m\.clf\.bz2:3000: the bzip2 data is truncated after this line"):
        for _ in CarmenLoader().load(path, parallel_bz2=parallel).frames():
            pass


def test_corrupt_bzip2(tmp_path: Path) -> None:
    data = bytearray(bz2.compress(("\n".join(GOOD.format(t=k) for k in range(2000)) + "\n").encode()))
    data[len(data) // 2] ^= 0xFF
    with pytest.raises(ParseError, match=r"c\.clf\.bz2: the bzip2 data is corrupt before its first line .* rejects"):
        run(tmp_path, bytes(data), "c.clf.bz2")
