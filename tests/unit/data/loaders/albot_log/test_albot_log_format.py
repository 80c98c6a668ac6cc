"""The robot's own log: exact round trips and one precise error per kind of bad line."""

from __future__ import annotations

import gzip
import math
import re
from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import DataError, ParseError
from albot1.data.loaders.albot_log.loader import AlbotLogLoader, AlbotLogWriter, view_line
from albot1.data.loaders.registry import loader_for
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata

ANGLES = np.deg2rad(np.arange(-90.0, 90.5, 0.5))
HEADER = "ALBOT1-LOG 1\nUNITS length=m angle=rad time=s\nFRAME thesis\n"
SENSOR3 = "SENSOR 3 10.0 -1.5707963267948966 1.5707963267948966\n"


def synthetic(n: int = 25, seed: int = 3) -> Sequence:
    rng = np.random.default_rng(seed)
    frames = []
    for i in range(n):
        angles = ANGLES if i < n // 2 else np.sort(rng.uniform(-2.0, 2.0, 90))  # geometry changes mid-log
        ranges = np.round(rng.uniform(0.0, 40.0, angles.shape[0]), 2)
        ranges[rng.random(angles.shape[0]) < 0.2] = np.nan
        ref = np.array([0.5 * i, 1.0, -3.0])  # every view or none: a log of both is refused
        frames.append(Frame(i, Scan(ranges, angles, 12.5 + 0.1 * i, 40.0), np.array([0.1 * i, 0.2 * i, 7.0 - i]), ref))
    return Sequence.from_frames("office run", frames)


def load_text(tmp_path: Path, text: str, name: str = "log.albotlog") -> list[Frame]:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return list(AlbotLogLoader().load(path).frames())


@pytest.mark.parametrize("name", ["run.albotlog", "run.albotlog.gz"])
def test_round_trip_is_exact(tmp_path: Path, name: str) -> None:
    seq = synthetic()
    AlbotLogWriter().write(seq, tmp_path / name)
    assert AlbotLogLoader().sniff(tmp_path / name)
    assert isinstance(loader_for(tmp_path / name), AlbotLogLoader)  # the registry's sniffing finds it
    loaded = AlbotLogLoader().load(tmp_path / name)
    assert loaded.name == "office run" and loaded.metadata.format == "albot-log"
    for a, b in zip(seq.frames(), loaded.frames(), strict=True):
        assert np.array_equal(a.scan.ranges.astype(np.float32), b.scan.ranges.astype(np.float32), equal_nan=True)
        assert np.allclose(a.scan.ranges, b.scan.ranges, rtol=1e-15, atol=0, equal_nan=True)
        assert np.max(np.abs(a.scan.angles - b.scan.angles)) < 1e-12
        assert b.scan.timestamp == a.scan.timestamp and b.scan.max_range == a.scan.max_range
        assert np.array_equal(a.odometry, b.odometry)  # unwrapped headings are kept as written
        assert (a.reference is None and b.reference is None) or np.array_equal(a.reference, b.reference)


def test_points_are_thesis_frame_left_to_right() -> None:
    scan = Scan(np.array([1.0, 2.0, np.nan]), np.array([-math.pi / 2, 0.0, math.pi / 2]), 3.0, 5.0)
    tokens = view_line(Frame(0, scan, np.zeros(3))).split()
    assert tokens[:7] == ["VIEW", "0", "3.0", "0.0", "0.0", "0.0", "-"]
    points = np.array([float(t) for t in tokens[7:]]).reshape(3, 2)
    assert np.isnan(points[0]).all()  # leftmost beam (+90 deg) first, no return
    assert points[1] == pytest.approx([0.0, 2.0])  # straight ahead is +y
    assert points[2] == pytest.approx([1.0, 0.0])  # the right-hand beam is +x


def test_a_hand_written_log_loads(tmp_path: Path) -> None:
    frames = load_text(
        tmp_path,
        HEADER
        + "# comment\n\nNAME demo\n"
        + SENSOR3
        + "VIEW 0 0.0 0.0 0.0 0.0 0.0 0.0 0.0 -2.0 0.0 0.0 3.5 nan nan\n"
        + "VIEW 1 0.5 0.25 0.0 0.0 1.0 2.0 0.01 -1.75 0.0 0.0 3.25 1.5 0.0\n",
    )
    assert [f.index for f in frames] == [0, 1]
    assert np.allclose(frames[0].scan.ranges, [np.nan, 3.5, 2.0], equal_nan=True)
    assert frames[0].reference == pytest.approx([0.0, 0.0, 0.0]) and frames[1].reference == pytest.approx(
        [1.0, 2.0, 0.01]
    )
    assert frames[1].scan.ranges == pytest.approx([1.5, 3.25, 1.75])


@pytest.mark.parametrize("gap", ["\t", " \t ", "  ", "\x0b"], ids=["tab", "mixed", "two-spaces", "vtab"])
def test_header_fields_are_split_by_any_whitespace_as_views_are(tmp_path: Path, gap: str) -> None:
    """A header written with tabs (a spreadsheet, a hand edit) reads as the space-separated one; the tab used
    to make the whole line one unknown keyword ('UNITS\\tlength=m...')."""
    header = (
        f"ALBOT1-LOG{gap}1\nUNITS{gap}length=m{gap}angle=rad{gap}time=s\nFRAME{gap}thesis\nNAME{gap}my{gap}demo\n"
        f"SENSOR{gap}3{gap}10.0{gap}-1.5707963267948966{gap}1.5707963267948966\n"
    )
    path = tmp_path / "log.albotlog"
    path.write_text(header + "VIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5 nan nan\n")
    sequence = AlbotLogLoader().load(path)
    assert sequence.name == "my demo"
    assert np.allclose(next(iter(sequence.frames())).scan.ranges, [np.nan, 3.5, 2.0], equal_nan=True)


def test_the_example_in_the_docs_loads(tmp_path: Path) -> None:
    doc = (Path(__file__).resolve().parents[5] / "docs" / "formats.md").read_text(encoding="utf-8")
    match = re.search(r"```text\n(ALBOT1-LOG 1\n.*?)```", doc, re.S)
    assert match, "docs/formats.md must hold an albot-log example in a ```text block"
    frames = load_text(tmp_path, match.group(1))
    assert len(frames) >= 2


def test_views_are_ordered_by_index_and_timestamps_kept_as_recorded(tmp_path: Path) -> None:
    # Public logs repeat stamps or jitter backwards (Intel); the log records them, the index orders the views.
    frames = load_text(
        tmp_path,
        HEADER + SENSOR3 + "VIEW 0 1.0 0 0 0 - nan nan nan nan nan nan\n"
        "VIEW 1 0.5 0 0 0 - nan nan nan nan nan nan\nVIEW 2 0.5 0 0 0 - nan nan nan nan nan nan\n",
    )
    assert [f.scan.timestamp for f in frames] == [1.0, 0.5, 0.5]


BAD_VIEWS = [
    ("VIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5\n", 5, "expected 'VIEW <index>"),
    ("VIEW 1 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5 nan nan\n", 5, "expected view index 0, got '1'"),
    ("VIEW 0 0.0 0.0 abc 0.0 - -2.0 0.0 0.0 3.5 nan nan\n", 5, "'abc' is not a number"),
    ("VIEW 0 nan 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5 nan nan\n", 5, "must be finite"),
    ("VIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5 nan 1.0\n", 5, "'nan nan' for a beam without return"),
    ("VIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 3.5 0.0 nan nan\n", 5, "point 2 (3.5, 0.0) is 3.5 m off its beam"),
    ("VIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 -3.5 nan nan\n", 5, "point 2 (0.0, -3.5) lies behind the robot"),
    ("VIEW 0 0.0 0.0 0.0 0.0 - -12.0 0.0 0.0 3.5 nan nan\n", 5, "beyond the max range 10.0 m"),
    ("SENSOR 2 10.0 0.0 0.1\nVIEW 0 0.0 0 0 0 - nan nan nan nan nan nan\n", 6, "4 point coordinates (2 beams)"),
    ("SCAN 0 1 2\n", 5, "unknown record 'SCAN'"),
]


@pytest.mark.parametrize(("body", "line", "message"), BAD_VIEWS)
def test_bad_records_name_file_line_and_expectation(tmp_path: Path, body: str, line: int, message: str) -> None:
    with pytest.raises(ParseError) as info:
        load_text(tmp_path, HEADER + SENSOR3 + body)
    assert info.value.line == line
    assert str(info.value).startswith(f"{tmp_path / 'log.albotlog'}:{line}: ")
    assert message in str(info.value)


BAD_HEADERS = [
    ("", 1, "empty file"),
    ("FLASER 180 1 2 3\n", 1, "expected the first line 'ALBOT1-LOG 1'"),
    ("ALBOT1-LOG 2\n", 1, "unsupported ALBOT1-LOG version '2'"),
    ("ALBOT1-LOG 1\nUNITS length=mm angle=rad time=s\n", 2, "no other units are defined"),
    ("ALBOT1-LOG 1\nFRAME rep103\n", 2, "expected 'FRAME thesis'"),
    ("ALBOT1-LOG 1\nUNITS length=m angle=rad time=s\n" + SENSOR3, 3, "the header lacks FRAME"),
    ("ALBOT1-LOG 1\nCOLOR red\n", 2, "unknown header line 'COLOR'"),
    (HEADER + "SENSOR 3 10.0 0.0 -0.1\n", 4, "strictly increasing"),
    (HEADER + "SENSOR 0 10.0 0.0 0.1\n", 4, "beams an integer from 1 to 100000"),
    (HEADER + "SENSOR 999999999999 10.0 0.0 0.1\n", 4, "beams an integer from 1 to 100000"),
    (HEADER + "SENSOR 3 -1.0 0.0 0.1\n", 4, "positive max range"),
    (HEADER + "SENSOR-ANGLES 3 10.0 0.0 0.1\n", 4, "expected 6 fields"),
    (HEADER + "VIEW 0 0 0 0 0 -\n", 4, "VIEW before any SENSOR line"),
]


@pytest.mark.parametrize(("text", "line", "message"), BAD_HEADERS)
def test_bad_headers(tmp_path: Path, text: str, line: int, message: str) -> None:
    with pytest.raises(ParseError) as info:
        load_text(tmp_path, text)
    assert info.value.line == line and message in str(info.value)


def test_truncated_gzip_and_binary_garbage(tmp_path: Path) -> None:
    AlbotLogWriter().write(synthetic(), tmp_path / "full.albotlog.gz")
    data = (tmp_path / "full.albotlog.gz").read_bytes()
    (tmp_path / "cut.albotlog.gz").write_bytes(data[: len(data) // 2])
    with pytest.raises(ParseError, match=r"cut.albotlog.gz:\d+: the gzip data is truncated after this line"):
        list(AlbotLogLoader().load(tmp_path / "cut.albotlog.gz").frames())
    (tmp_path / "bin.albotlog").write_bytes(b"ALBOT1-LOG 1\n\xff\xfe\x00")
    with pytest.raises(ParseError, match=r"bin.albotlog:2: not UTF-8 text"):
        AlbotLogLoader().load(tmp_path / "bin.albotlog")
    assert not AlbotLogLoader().sniff(tmp_path / "cut.albotlog")  # absent
    with gzip.open(tmp_path / "other.gz", "wt") as fh:
        fh.write("FLASER 3 1 2 3\n")
    assert not AlbotLogLoader().sniff(tmp_path / "other.gz")


def test_numpy_scalars_are_written_as_plain_numbers(tmp_path: Path) -> None:
    scan = Scan(np.array([1.0, 2.0]), np.array([0.0, 0.5]), np.float64(3.25), np.float64(8.0))  # type: ignore[arg-type]
    AlbotLogWriter().write(Sequence.from_frames("np", [Frame(0, scan, np.zeros(3))]), tmp_path / "np.albotlog")
    text = (tmp_path / "np.albotlog").read_text(encoding="utf-8")
    assert "np.float64" not in text
    frame = next(AlbotLogLoader().load(tmp_path / "np.albotlog").frames())
    assert frame.scan.timestamp == 3.25 and frame.scan.max_range == 8.0


def test_writer_checks(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="exists already"):
        (tmp_path / "x.albotlog").write_text("")
        AlbotLogWriter().write(synthetic(2), tmp_path / "x.albotlog")
    frame = Frame(0, Scan(np.array([1.0, -0.5]), np.array([0.0, 0.1]), 0.0, 10.0), np.zeros(3))
    with pytest.raises(DataError, match=r"scan #0: VIEW range 2 is -0.5, expected ranges in \[0, max_range=10.0\]"):
        AlbotLogWriter().write(Sequence.from_frames("neg", [frame]), tmp_path / "neg.albotlog")
    assert not (tmp_path / "neg.albotlog").exists()
    with pytest.raises(DataError, match="takes no loading options"):
        AlbotLogWriter().write(synthetic(2), tmp_path / "ok.albotlog")
        AlbotLogLoader().load(tmp_path / "ok.albotlog", scan_topic="/scan")


def test_the_laser_mount_survives_a_round_trip_and_a_bad_mount_line_is_refused(tmp_path: Path) -> None:
    """A source whose laser sits off the robot's centre (a bag's /tf_static, fr-clinic's 0.22 m, a rear laser's
    half turn) used to lose its mount in an albot log without a word: read back, every scan was placed at the
    robot's centre, facing forwards (converting fr-clinic moved each scan 0.22 m). The log's MOUNT line keeps it."""
    frames = [Frame(i, Scan(np.ones(3), np.array([-0.5, 0.0, 0.5]), float(i), 10.0), np.zeros(3)) for i in range(2)]
    mount = (0.22, -0.05, math.pi)
    seq = Sequence.from_frames("m", frames, SequenceMetadata(sensor_offset=mount))
    AlbotLogWriter().write(seq, tmp_path / "m.albotlog")
    assert AlbotLogLoader().load(tmp_path / "m.albotlog").metadata.sensor_offset == mount
    AlbotLogWriter().write(Sequence.from_frames("z", frames), tmp_path / "z.albotlog")  # no mount: no MOUNT line
    assert "MOUNT" not in (tmp_path / "z.albotlog").read_text()
    assert AlbotLogLoader().load(tmp_path / "z.albotlog").metadata.sensor_offset == (0.0, 0.0, 0.0)
    for bad, message in (("MOUNT 0.2 0.1", r"expected 'MOUNT <x> <y> <theta>'"), ("MOUNT 0.2 nan 0", "finite")):
        path = tmp_path / "bad.albotlog"
        path.write_text(HEADER + bad + "\n" + SENSOR3 + "VIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5 nan nan\n")
        with pytest.raises(ParseError, match=rf"bad\.albotlog:4: .*{message}"):
            AlbotLogLoader().load(path)
