"""A header line repeated with another value is refused naming both lines (it used to be: the last one won).

A log whose header says ``MOUNT 0.2 0 0`` and then ``MOUNT 0.5 0 0`` (two recordings' headers joined, or an
edit that added a line) was read with the second mount and no word, every scan placed 0.3 m off.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.data.errors import ParseError
from albot1.data.loaders.albot_log.loader import AlbotLogLoader

HEADER = "ALBOT1-LOG 1\nUNITS length=m angle=rad time=s\nFRAME thesis\n"
BODY = "SENSOR 3 10.0 -1.5707963267948966 1.5707963267948966\nVIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5 nan nan\n"


@pytest.mark.parametrize(
    ("lines", "message"),
    [
        ("MOUNT 0.2 0.0 0.0\nMOUNT 0.5 0.0 0.0\n", "MOUNT '0.5 0.0 0.0', but line 4 says MOUNT '0.2 0.0 0.0'"),
        ("NAME office\n# a comment\nNAME corridor\n", "NAME 'corridor', but line 4 says NAME 'office'"),
    ],
)
def test_conflicting_header_lines_are_refused(tmp_path: Path, lines: str, message: str) -> None:
    path = tmp_path / "two.albotlog"
    path.write_text(HEADER + lines + BODY)
    with pytest.raises(ParseError, match=rf"two\.albotlog:(5|6): {message}; expected one"):
        AlbotLogLoader().load(path)


def test_a_header_line_repeated_with_its_value_is_read(tmp_path: Path) -> None:
    path = tmp_path / "same.albotlog"
    repeated = "MOUNT 0.2 0.0 0.0\nNAME run\nMOUNT  0.2\t0.0 0.0\nUNITS length=m angle=rad time=s\n"
    path.write_text(HEADER + repeated + BODY)
    loaded = AlbotLogLoader().load(path)
    assert loaded.metadata.sensor_offset == (0.2, 0.0, 0.0) and loaded.name == "run"
    assert len(list(loaded.frames())) == 1
