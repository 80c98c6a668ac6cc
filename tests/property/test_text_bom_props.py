"""A leading UTF-8 byte-order mark changes nothing: every text reader reads a file with one exactly as
without (same values, or the same error at the same line), and the byte-stream filter drops it however the
stream is cut into pieces."""

from __future__ import annotations

import gzip
import tempfile
from collections.abc import Callable
from pathlib import Path

from hypothesis import assume, given, settings
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.loaders.albot_log.loader import AlbotLogLoader
from albot1.data.loaders.carmen.loader import CarmenLoader
from albot1.data.relations import read_relations
from albot1.data.text import UTF8_BOM, without_bom
from albot1.data.trajectory import read_trajectory


def _frames(path: Path, loader: CarmenLoader | AlbotLogLoader) -> object:
    frames = list(loader.load(path).frames())
    return [(f.scan.timestamp, f.scan.ranges.tolist(), f.scan.angles.tolist(), f.odometry.tolist()) for f in frames]


def _relations(path: Path) -> object:
    r = read_relations(path)
    return (r.t1.tolist(), r.t2.tolist(), r.poses.tolist())


def _trajectory(fmt: str) -> Callable[[Path], object]:
    def read(path: Path) -> object:
        file = read_trajectory(path, fmt)
        return (file.poses.tolist(), None if file.timestamps is None else file.timestamps.tolist())

    return read


#: file name -> reader; each returns plain values (compared with ==, NaN written as a string)
READERS: dict[str, Callable[[Path], object]] = {
    "log.clf": lambda p: _frames(p, CarmenLoader()),
    "log.clf.gz": lambda p: _frames(p, CarmenLoader()),
    "log.albotlog": lambda p: _frames(p, AlbotLogLoader()),
    "log.albotlog.gz": lambda p: _frames(p, AlbotLogLoader()),
    "poses.tum": _trajectory("tum"),
    "poses.kitti": _trajectory("kitti"),
    "r.relations": _relations,
}

NUMBER = st.one_of(
    st.floats(-1e3, 1e3, allow_nan=False).map(repr), st.integers(0, 400).map(str), st.sampled_from(["nan", "1_0"])
)
WORD = st.sampled_from(
    ["FLASER", "ODOM", "PARAM", "ALBOT1-LOG", "UNITS", "FRAME", "SENSOR", "VIEW", "-", "host", "#", "\ufeff"]
)
LINE = st.lists(st.one_of(NUMBER, WORD), max_size=12).map(" ".join)
#: valid files of each kind, so that the property also covers accepted input, not only errors
VALID = {
    "log.clf": "FLASER 3 1.0 2.0 3.0 0 0 0 0.5 0 0.1 {t} host {t}",
    "log.albotlog": "",
    "poses.tum": "{t} 1.0 2.0 0 0 0 0.1986693307950612 0.9800665778412416",
    "poses.kitti": "1 0 0 {t} 0 1 0 2.0 0 0 1 0",
    "r.relations": "{t} {u} 0.5 0.1 0 0 0 0.2",
}
ALBOT_HEAD = "ALBOT1-LOG 1\nUNITS length=m angle=rad time=s\nFRAME thesis\nSENSOR 3 20.0 -1.0 1.0\n"


def valid_text(name: str, count: int) -> str:
    base = name.removesuffix(".gz")
    if base == "log.albotlog":
        views = [f"VIEW {i} {i + 1.0} 0.0 0.0 0.0 - nan nan 0.0 2.0 nan nan" for i in range(count)]
        return ALBOT_HEAD + "".join(v + "\n" for v in views)
    return "".join(VALID[base].format(t=float(i + 1), u=float(i + 2)) + "\n" for i in range(count))


def outcome(path: Path, read: Callable[[Path], object]) -> tuple[str, str]:
    """``("ok", values)`` or ``("error", message)``, the folder left out so two folders compare."""
    try:
        return "ok", repr(read(path))
    except DataError as exc:
        return "error", str(exc).replace(str(path.parent), "<dir>")


def _write(path: Path, data: bytes) -> None:
    path.write_bytes(gzip.compress(data) if path.name.endswith(".gz") else data)


@settings(max_examples=150, deadline=None)
@given(
    name=st.sampled_from(sorted(READERS)),
    valid=st.integers(0, 4),
    extra=st.lists(LINE, max_size=3),
    where=st.integers(0, 10),
)
def test_a_leading_byte_order_mark_reads_exactly_as_without(
    name: str, valid: int, extra: list[str], where: int
) -> None:
    lines = valid_text(name, valid).splitlines()
    at = min(where, len(lines))
    text = "\n".join(lines[:at] + extra + lines[at:]) + "\n"
    data = text.encode("utf-8")
    assume(not data.startswith(UTF8_BOM))  # one mark is dropped; a second one is a character of the line
    with tempfile.TemporaryDirectory() as plain_dir, tempfile.TemporaryDirectory() as bom_dir:
        plain, marked = Path(plain_dir) / name, Path(bom_dir) / name
        _write(plain, data)
        _write(marked, UTF8_BOM + data)
        expected = outcome(plain, READERS[name])
        assert outcome(marked, READERS[name]) == expected
    if not extra:
        assert expected[0] == "ok" or valid == 0, expected  # the valid files are read


@given(data=st.binary(max_size=40), marked=st.booleans(), cuts=st.lists(st.integers(0, 43), max_size=6))
def test_without_bom_drops_only_a_leading_mark_however_the_bytes_are_cut(
    data: bytes, marked: bool, cuts: list[int]
) -> None:
    stream = (UTF8_BOM if marked else b"") + data
    edges = [0, *sorted(min(c, len(stream)) for c in cuts), len(stream)]
    pieces = [stream[a:b] for a, b in zip(edges, edges[1:], strict=False)]
    expected = stream[len(UTF8_BOM) :] if stream.startswith(UTF8_BOM) else stream
    assert b"".join(without_bom(pieces)) == expected


def test_the_valid_files_of_the_property_are_read() -> None:
    """The property's valid files must be accepted, or it would compare only errors."""
    with tempfile.TemporaryDirectory() as folder:
        for name, read in READERS.items():
            path = Path(folder) / name
            _write(path, (UTF8_BOM + valid_text(name, 3).encode()))
            kind, values = outcome(path, read)
            assert kind == "ok", values
