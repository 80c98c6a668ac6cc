"""``?relations=FILE`` and ``?reference=FILE`` on every source format (albot1.data.attach via open_sequence)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.data.convert import convert
from albot1.data.errors import DataError
from albot1.data.model import Relations
from albot1.data.open import open_sequence
from albot1.data.relations import write_relations
from albot1.data.trajectory import write_tum

WORLD = "synthetic-square-startstop"
FORMATS = {
    "carmen": "w.clf",
    "albot-log": "w.albotlog",
    "ros1": "w.bag",
    "ros2-sqlite3": "w-sqlite",
    "ros2-mcap": "w-mcap",
}


@pytest.fixture(scope="module")
def sources(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The world written in every format the converter writes (the world's first 40 scans)."""
    folder = tmp_path_factory.mktemp("sources")
    out = {}
    for fmt, name in FORMATS.items():
        convert(f"{WORLD}[:40]", folder / name, fmt)
        out[fmt] = folder / name
    return out


def _own_files(folder: Path, stamps: np.ndarray) -> tuple[Path, Path, np.ndarray]:
    poses = np.column_stack([np.arange(len(stamps)) * 0.5, np.full(len(stamps), 2.0), np.full(len(stamps), 0.25)])
    reference = folder / "gt.tum"
    write_tum(reference, stamps, poses)
    relations = folder / "own.relations"
    write_relations(relations, Relations(stamps[:2].copy(), stamps[1:3].copy(), np.array([[0.5, 0, 0], [0.5, 0, 0]])))
    return reference, relations, poses


@pytest.mark.parametrize("fmt", ["world", *FORMATS])
def test_every_source_takes_a_relations_file_and_a_reference_file(
    fmt: str, sources: dict[str, Path], tmp_path: Path
) -> None:
    source = f"{WORLD}[:40]" if fmt == "world" else str(sources[fmt])
    stamps = open_sequence(source).arrays.timestamps
    reference, relations, poses = _own_files(tmp_path, stamps)
    if fmt == "world":
        ref = f"{WORLD}?relations={relations}&reference={reference}[:40]"
    else:
        ref = f"{source}?relations={relations}&reference={reference}"
    sequence = open_sequence(ref)
    assert sequence.relations is not None and len(sequence.relations) == 2
    assert np.array_equal(sequence.relations.t1, np.round(stamps[:2], 9))
    got = sequence.arrays.reference
    assert got is not None and np.abs(got - poses).max() < 1e-8
    assert str(reference) in sequence.metadata.reference_source


def test_a_scan_without_a_reference_pose_is_named(tmp_path: Path) -> None:
    stamps = open_sequence(f"{WORLD}[:10]").arrays.timestamps
    reference, _, _ = _own_files(tmp_path, stamps[:5])
    with pytest.raises(DataError, match=r"gt.tum: no pose within 0.01 s of scan 5 of"):
        open_sequence(f"{WORLD}?reference={reference}[:10]").arrays  # noqa: B018
    assert open_sequence(f"{WORLD}?reference={reference}&reference_max_dt=100[:10]").arrays.reference is not None


def test_kitti_reference_needs_one_pose_per_scan(tmp_path: Path, sources: dict[str, Path]) -> None:
    kitti = tmp_path / "gt.kitti"
    kitti.write_text("1 0 0 1 0 1 0 2 0 0 1 0\n" * 3)
    got = open_sequence(f"{WORLD}?reference={kitti}[:3]").arrays.reference
    assert got is not None and np.array_equal(got, [[1.0, 2.0, 0.0]] * 3)
    with pytest.raises(DataError, match=r"gt.kitti: 3 poses \(kitti, no timestamps\), but .* has more scans"):
        open_sequence(f"{WORLD}?reference={kitti}[:4]").arrays  # noqa: B018
    kitti.write_text("1 0 0 1 0 1 0 2 0 0 1 0\n" * 41)
    with pytest.raises(DataError, match=r"gt.kitti: 41 poses \(kitti, no timestamps\), but .* has 40 scans"):
        open_sequence(f"{sources['carmen']}?reference={kitti}").arrays  # noqa: B018


@pytest.mark.parametrize(
    ("query", "message"),
    [
        ("relations=/no/such/file", "relations=/no/such/file: no such file"),
        ("reference=/no/such/file", "reference=/no/such/file: no such file"),
        ("reference=/", "/: a folder, not a regular file; expected a regular file for the option reference="),
        ("reference_max_dt=1", "reference_max_dt goes with reference=FILE"),
    ],
)
def test_bad_own_file_options_are_one_line(query: str, message: str) -> None:
    with pytest.raises(DataError, match=message):
        open_sequence(f"{WORLD}?{query}")


def test_bad_reference_max_dt(tmp_path: Path) -> None:
    reference, _, _ = _own_files(tmp_path, np.arange(5.0))
    with pytest.raises(DataError, match="reference_max_dt=-1; expected a positive number of seconds"):
        open_sequence(f"{WORLD}?reference={reference}&reference_max_dt=-1")


def test_unknown_option_errors_list_the_options_of_every_source(sources: dict[str, Path]) -> None:
    for fmt in ("carmen", "ros1", "ros2-sqlite3", "ros2-mcap"):
        with pytest.raises(DataError, match=r"unknown .*relations, relations_repeats, (reference, )?reference_max_dt"):
            open_sequence(f"{sources[fmt]}?bogus=1")
    with pytest.raises(DataError, match=r"options of every source: relations, relations_repeats, reference"):
        open_sequence(f"{WORLD}?bogus=1")


def test_carmen_reference_keywords_still_reach_the_loader(sources: dict[str, Path]) -> None:
    assert open_sequence(f"{sources['carmen']}?reference=none").arrays.reference is None


def test_relations_repeats_goes_with_a_relations_file_on_every_source(sources: dict[str, Path], tmp_path: Path) -> None:
    """`?relations=FILE&relations_repeats=keep` counts a repeated line as listed; the default counts it once."""
    relations = tmp_path / "twice.relations"
    relations.write_text("0 0.2 1 0 0 0 0 0\n0 0.2 1 0 0 0 0 0\n")
    for path in sources.values():
        default = open_sequence(f"{path}?relations={relations}")
        kept = open_sequence(f"{path}?relations={relations}&relations_repeats=keep")
        assert default.relations is not None and kept.relations is not None
        assert (len(default.relations), default.relations.repeats, default.relations.repeats_counted) == (1, 1, False)
        assert (len(kept.relations), kept.relations.repeats, kept.relations.repeats_counted) == (2, 1, True)
        with pytest.raises(DataError, match=r"relations_repeats='twice'; expected drop"):
            open_sequence(f"{path}?relations={relations}&relations_repeats=twice")


def test_relations_of_another_log_are_refused_on_the_first_full_pass(sources: dict[str, Path], tmp_path: Path) -> None:
    """No relation stamp within the log's time (another log's file) is refused; partial overlap is kept."""
    foreign = tmp_path / "other-log.relations"
    foreign.write_text("976052905.167303 976052911.885496 1 0 0 0 0 0\n976052896.784509 976052905.167303 1 0 0 0 0 0\n")
    stamps = open_sequence(sources["carmen"]).arrays.timestamps
    sequence = open_sequence(f"{sources['carmen']}?relations={foreign}")
    assert sequence.relations is not None and len(sequence.relations) == 2  # attaching reads the file only
    expected = (
        f"{foreign}: its 2 relations span 976052896.785-976052911.885 s, but the scans of {str(sources['carmen'])!r} "
        f"span {stamps.min():.3f}-{stamps.max():.3f} s: no relation lies within the log's time; expected the "
        "relations of this log"
    )
    with pytest.raises(DataError) as caught:
        sequence.arrays  # noqa: B018 - the one full pass over the scans
    assert str(caught.value) == expected
    # one end within the log's time (within the matching tolerance) is overlap: counted, as before
    partial = tmp_path / "partial.relations"
    partial.write_text(f"{float(stamps[-1]) + 5e-5!r} 976052911.885496 1 0 0 0 0 0\n")
    assert len(open_sequence(f"{sources['carmen']}?relations={partial}").arrays.timestamps) == len(stamps)
    # a slice stops before the end of the log: its relations may lie beyond it, so it is not refused here
    assert len(open_sequence(f"{sources['carmen']}?relations={foreign}[:10]").arrays.timestamps) == 10


def test_a_relation_end_between_two_scans_is_refused_on_the_first_full_pass(
    sources: dict[str, Path], tmp_path: Path
) -> None:
    """An end within the log's time that is no scan's stamp: refused, never left out as "outside the run".

    Before, the relation metric matched it to no scan (0.1 ms) and left it out as naming a scan the run did not
    see: a file whose stamps were rounded to milliseconds scored a subset of its relations without an error.
    """
    stamps = open_sequence(sources["carmen"]).arrays.timestamps
    good = f"{float(stamps[1])!r} {float(stamps[4])!r} 1 0 0 0 0 0\n"
    mid = (float(stamps[5]) + float(stamps[6])) / 2
    between = tmp_path / "between.relations"
    between.write_text(good + f"{float(stamps[2])!r} {mid!r} 1 0 0 0 0 0\n")
    for path in sources.values():
        with pytest.raises(DataError, match=r"1 of its 2 relations have an end within the time of .* that is no "):
            open_sequence(f"{path}?relations={between}").arrays  # noqa: B018 - the one full pass over the scans
        with pytest.raises(DataError, match=rf"relation 2 \({float(stamps[2]):.6f} -> {mid:.6f}\)"):
            open_sequence(f"{path}?relations={between}[::2]").arrays  # noqa: B018 - a stride reads every scan
    exact = tmp_path / "exact.relations"
    exact.write_text(good)
    assert len(open_sequence(f"{sources['carmen']}?relations={exact}").arrays.timestamps) == len(stamps)
