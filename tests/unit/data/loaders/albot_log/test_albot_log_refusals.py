"""Issue 15, albot log: a log without views is refused at load time, and the writer refuses every frame
its reader would refuse (the same rules, :func:`sensor_problem` / :func:`view_problem`)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.convert import convert
from albot1.data.errors import ParseError, UnwritableError
from albot1.data.loaders.albot_log.loader import AlbotLogLoader, AlbotLogWriter
from albot1.data.model import Frame, Scan, Sequence

HEADER = "ALBOT1-LOG 1\nUNITS length=m angle=rad time=s\nFRAME thesis\n"


def test_a_log_without_views_is_refused_when_loaded(tmp_path: Path) -> None:
    path = tmp_path / "empty.albotlog"
    path.write_text(HEADER + "NAME x\nSENSOR 3 10.0 -0.5 0.5\n# no views\n")
    with pytest.raises(ParseError, match=r"empty\.albotlog:6: the log holds no VIEW line, so no scans"):
        AlbotLogLoader().load(path)


def one(scan: Scan, odometry: np.ndarray | None = None) -> Sequence:
    return Sequence.from_frames("s", [Frame(0, scan, np.zeros(3) if odometry is None else odometry)])


ANGLES = np.array([-0.5, 0.0, 0.5])


@pytest.mark.parametrize(
    ("sequence", "message"),
    [
        (one(Scan(np.ones(3), ANGLES[::-1].copy(), 0.0, 10.0)), r"SENSOR beam angles must be strictly increasing"),
        (one(Scan(np.ones(3), np.array([0.0, math.nan, 1.0]), 0.0, 10.0)), r"SENSOR beam angles must be finite"),
        (one(Scan(np.ones(3), ANGLES, 0.0, 0.0)), r"SENSOR max range is 0\.0, expected a finite, positive"),
        (one(Scan(np.zeros(0), np.zeros(0), 0.0, 10.0)), r"SENSOR 0 beams, expected 1 to 100000"),
        (one(Scan(np.array([1.0, math.inf, 1.0]), ANGLES, 0.0, 10.0)), r"VIEW range 2 is inf, expected ranges in"),
        (one(Scan(np.array([1.0, 12.0, 1.0]), ANGLES, 0.0, 10.0)), r"VIEW range 2 is 12\.0, expected ranges in"),
        (one(Scan(np.ones(3), ANGLES, math.nan, 10.0)), r"VIEW the timestamp and poses must be finite"),
        (one(Scan(np.ones(3), ANGLES, 0.0, 10.0), np.array([0.0, math.inf, 0.0])), r"VIEW the timestamp and poses"),
        (Sequence.from_frames("e", []), r"the sequence has no scans"),
    ],
)
def test_the_writer_refuses_what_the_reader_refuses(tmp_path: Path, sequence: Sequence, message: str) -> None:
    with pytest.raises(UnwritableError, match=r"out\.albotlog: .*" + message):
        AlbotLogWriter().write(sequence, tmp_path / "out.albotlog")
    assert list(tmp_path.iterdir()) == []


def test_negative_beam_spacing_cannot_be_converted_into_a_log_the_reader_refuses(tmp_path: Path) -> None:
    """The reported case: a clockwise scan written as an albot log that its own reader then refused."""
    frames = [Frame(i, Scan(np.ones(5), np.linspace(1.0, -1.0, 5), float(i), 10.0), np.zeros(3)) for i in range(3)]
    with pytest.raises(
        UnwritableError, match=r"neg\.albotlog: scan #0: SENSOR beam angles must be strictly increasing"
    ):
        convert(Sequence.from_frames("neg", frames), tmp_path / "neg.albotlog")
    assert not (tmp_path / "neg.albotlog").exists()


def test_a_number_in_python_s_digit_grouping_is_refused_at_its_line_not_read(tmp_path: Path) -> None:
    """``float("1_0")`` is 10.0: a log's typo would silently become a range ten times too far (CARMEN refuses it)."""
    path = tmp_path / "g.albotlog"
    frames = [Frame(i, Scan(np.ones(3), ANGLES, float(i), 10.0), np.zeros(3)) for i in range(2)]
    AlbotLogWriter().write(Sequence.from_frames("g", frames), path)
    lines = path.read_text().splitlines()
    view = next(i for i, text in enumerate(lines) if text.startswith("VIEW"))
    fields = lines[view].split()
    fields[-1] = "1_0"
    lines[view] = " ".join(fields)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ParseError, match=rf"g\.albotlog:{view + 1}: .*'1_0' is not a number"):
        AlbotLogLoader().load(path).frames().__next__()


@pytest.mark.parametrize("first_has", [False, True])
def test_a_log_where_only_some_views_have_a_reference_is_refused_not_read_without_any(
    tmp_path: Path, first_has: bool
) -> None:
    """A run scores reference poses only when every scan has one: a log with some '-' views used to load and
    lose every reference pose it held ("the dataset has no reference poses"), without a word."""
    views = [
        "VIEW 0 0.0 0.0 0.0 0.0 " + ("1.0 2.0 0.0" if first_has else "-") + " 0.0 1.0 0.0 1.0 0.0 1.0",
        "VIEW 1 0.5 0.1 0.0 0.0 1.1 2.0 0.0 0.0 1.0 0.0 1.0 0.0 1.0",
        "VIEW 2 1.0 0.2 0.0 0.0 - 0.0 1.0 0.0 1.0 0.0 1.0",
    ]
    path = tmp_path / "part.albotlog"
    path.write_text(HEADER + "SENSOR-ANGLES 3 10.0 -0.001 0.0 0.001\n" + "\n".join(views) + "\n")
    line, has, lacks = (
        (7, "view 2 has none \\('-'\\)", "has a reference pose")
        if first_has
        else (6, "view 1 has a reference pose", "has none")
    )
    with pytest.raises(ParseError, match=rf"part\.albotlog:{line}: {has}, but view 0 \(line 5\) {lacks}"):
        list(AlbotLogLoader().load(path).frames())
    frames = [
        Frame(i, Scan(np.ones(3), ANGLES, float(i), 10.0), np.zeros(3), np.zeros(3) if i == 1 else None)
        for i in range(2)
    ]
    with pytest.raises(UnwritableError, match=r"frame 1 has a reference pose but frame 0 has none; an albot log"):
        AlbotLogWriter().write(Sequence.from_frames("p", frames), tmp_path / "out.albotlog")
