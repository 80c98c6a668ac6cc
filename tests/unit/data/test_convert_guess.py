"""Output format from the output name, and conversion of in-memory sequences."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.data.convert import convert, guess_format
from albot1.data.errors import UnknownFormatError
from albot1.data.loaders.registry import load
from albot1.data.model import Frame, Relations, Scan, Sequence, SequenceMetadata


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("a.bag", "ros1"),
        ("run.db3", "ros2-sqlite3"),
        ("run.MCAP", "ros2-mcap"),
        ("x.albotlog", "albot-log"),
        ("x.albotlog.gz", "albot-log"),
        ("aces.clf", "carmen"),
        ("aces.clf.bz2", "carmen"),
        ("intel.log.gz", "carmen"),
    ],
)
def test_guess_format(name: str, expected: str) -> None:
    assert guess_format(Path("/some/dir") / name) == expected


@pytest.mark.parametrize("name", ["run", "x.txt", "x.gz", "bag"])
def test_unknown_output_names_ask_for_format(name: str) -> None:
    with pytest.raises(UnknownFormatError, match="use --format or one of: .albotlog.gz"):
        guess_format(name)


def test_convert_counts_scans_and_honours_an_explicit_format(tmp_path: Path) -> None:
    angles = np.linspace(-1.0, 1.0, 11)
    frames = [Frame(i, Scan(np.full(11, 2.0 + i), angles, float(i), 20.0), np.array([i, 0.0, 0.0])) for i in range(4)]
    done = convert(Sequence.from_frames("tiny", frames), tmp_path / "tiny.txt", "albot-log")
    assert (done.scans, done.format_name, done.output) == (4, "albot-log", tmp_path / "tiny.txt")
    back = list(load(tmp_path / "tiny.txt").frames())
    assert [float(f.scan.ranges[0]) for f in back] == pytest.approx([2.0, 3.0, 4.0, 5.0], rel=1e-15)
    with pytest.raises(UnknownFormatError, match="unknown format 'ros3'"):
        convert(Sequence.from_frames("tiny", frames), tmp_path / "t.bag", "ros3")


def test_retime_shifts_only_repeated_or_backward_stamps(tmp_path: Path) -> None:
    angles = np.linspace(-1.0, 1.0, 5)
    times = [10.0, 10.0, 9.5, 12.0, 12.0000001]
    frames = [Frame(i, Scan(np.full(5, 1.0), angles, t, 5.0), np.array([i, 0.0, 0.0])) for i, t in enumerate(times)]
    done = convert(Sequence.from_frames("jitter", frames), tmp_path / "j.mcap", retime=True)
    assert done.retimed == 3
    back = [f.scan.timestamp for f in load(tmp_path / "j.mcap").frames()]
    assert back == pytest.approx([10.0, 10.000001, 10.000002, 12.0, 12.000001], abs=1e-9)
    assert [f.odometry[0] for f in load(tmp_path / "j.mcap").frames()] == [0.0, 1.0, 2.0, 3.0, 4.0]


def test_what_no_format_holds_is_named_not_dropped_silently(tmp_path: Path) -> None:
    angles = np.linspace(-1.0, 1.0, 5)
    frames = [Frame(i, Scan(np.full(5, 1.0), angles, float(i), 5.0), np.array([i, 0.0, 0.0])) for i in range(3)]
    relations = Relations(np.array([0.0, 1.0, 0.0]), np.array([1.0, 2.0, 2.0]), np.zeros((3, 3)))
    metadata = SequenceMetadata(
        license="CC-BY",
        extra={"wall_segments": 4, "spaces": [{"name": "a"}, {"name": "b"}], "doorways": [{}], "doorway_crossings": []},
    )
    done = convert(Sequence.from_frames("truth", frames, metadata, relations), tmp_path / "t.clf")
    assert done.not_carried == ("3 relations", "the floor plan (4 wall segments, 2 rooms, 1 doorways)", "licence")
    plain = convert(Sequence.from_frames("plain", frames, SequenceMetadata(citation="X")), tmp_path / "p.albotlog")
    assert plain.not_carried == ("citation",)
    assert convert(Sequence.from_frames("bare", frames), tmp_path / "b.albotlog").not_carried == ()
