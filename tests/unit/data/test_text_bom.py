"""A UTF-8 byte-order mark at the start of a text file is dropped by every text reader (``albot1.data.text``);
one anywhere else stays a character of its line and is refused there."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import ParseError
from albot1.data.loaders.registry import load
from albot1.data.relations import read_relations
from albot1.data.text import UTF8_BOM, without_bom
from albot1.data.trajectory import read_trajectory

CARMEN = (
    "# CARMEN log\n"
    "FLASER 3 1.0 2.0 3.0 0 0 0 0.5 0 0.1 1.0 host 1.0\n"
    "FLASER 3 1.0 2.5 3.0 0 0 0 0.6 0 0.1 2.0 host 2.0\n"
)
ALBOT = (
    "ALBOT1-LOG 1\nUNITS length=m angle=rad time=s\nFRAME thesis\nSENSOR 3 20.0 -1.0 1.0\n"
    "VIEW 0 1.0 0.5 0.0 0.1 - nan nan 0.0 2.0 nan nan\n"
)
TUM = "# t x y z qx qy qz qw\n1.0 1.0 2.0 0 0 0 0 1\n2.0 1.5 2.0 0 0 0 0 1\n"
KITTI = "1 0 0 1.0 0 1 0 2.0 0 0 1 0\n1 0 0 1.5 0 1 0 2.0 0 0 1 0\n"
RELATIONS = "1.0 2.0 0.5 0.1 0 0 0 0.2\n"


def write(path: Path, text: str, *, mark: bytes = UTF8_BOM) -> Path:
    data = mark + text.encode()
    path.write_bytes(gzip.compress(data) if path.suffix == ".gz" else data)
    return path


@pytest.mark.parametrize("name", ["log.clf", "log.clf.gz"])
def test_carmen_log(tmp_path: Path, name: str) -> None:
    marked = load(write(tmp_path / name, CARMEN))  # sniffed too: the format is found by content
    plain = load(write(tmp_path / f"plain-{name}", CARMEN, mark=b""))
    assert marked.metadata.format == "carmen"
    np.testing.assert_array_equal(marked.timestamps, plain.timestamps)
    assert marked.timestamps.tolist() == [1.0, 2.0]


@pytest.mark.parametrize("name", ["log.albotlog", "log.albotlog.gz"])
def test_albot_log(tmp_path: Path, name: str) -> None:
    sequence = load(write(tmp_path / name, ALBOT))
    assert sequence.metadata.format == "albot-log"
    frame = next(iter(sequence.frames()))
    assert frame.scan.timestamp == 1.0 and frame.odometry.tolist() == [0.5, 0.0, 0.1]


def test_tum_and_kitti_trajectories(tmp_path: Path) -> None:
    tum = read_trajectory(write(tmp_path / "t.tum", TUM))
    assert tum.timestamps is not None and tum.timestamps.tolist() == [1.0, 2.0]
    assert tum.poses.tolist() == [[1.0, 2.0, 0.0], [1.5, 2.0, 0.0]]
    assert read_trajectory(write(tmp_path / "t.kitti", KITTI)).poses.tolist() == [[1.0, 2.0, 0.0], [1.5, 2.0, 0.0]]


def test_relations_file(tmp_path: Path) -> None:
    relations = read_relations(write(tmp_path / "r.relations", RELATIONS))
    assert relations.t1.tolist() == [1.0] and relations.poses.tolist() == [[0.5, 0.1, 0.2]]


def test_a_mark_after_the_start_is_refused_at_its_line(tmp_path: Path) -> None:
    bad = CARMEN.replace("\nFLASER 3 1.0 2.5", "\n\ufeffFLASER 3 1.0 2.5")
    with pytest.raises(ParseError, match=r"log\.clf:3: expected a CARMEN message name .* found '\\ufeffFLASER 3"):
        list(load(write(tmp_path / "log.clf", bad)).frames())
    with pytest.raises(ParseError, match=r"t\.tum:3: value 1 is '\\ufeff2\.0', expected a number"):
        read_trajectory(write(tmp_path / "t.tum", TUM.replace("\n2.0", "\n\ufeff2.0")))
    with pytest.raises(ParseError, match=r"r\.relations:1: field '\\ufeff1\.0' is not a number"):
        read_relations(write(tmp_path / "r.relations", RELATIONS, mark=UTF8_BOM + UTF8_BOM))


def test_without_bom_holds_a_split_mark_back_until_decided() -> None:
    assert list(without_bom([b"\xef", b"\xbb", b"\xbfAB", b"C"])) == [b"AB", b"C"]
    assert list(without_bom([b"\xef", b"\xbbX"])) == [b"\xef\xbbX"]  # not a mark: handed on whole
    assert list(without_bom([b"", b"A"])) == [b"A"]
    assert list(without_bom([UTF8_BOM])) == []
