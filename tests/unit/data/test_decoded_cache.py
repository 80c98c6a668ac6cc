"""The decoded-log cache: frames read back bit-identical, keyed by content and options, damage rebuilt."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import numpy as np
import pytest

from albot1.data import decoded
from albot1.data.model import Frame
from albot1.data.open import open_sequence


def _log(path: Path, scans: int, *, shift: float = 0.0, mtime: int = 1_000_000_000) -> Path:
    """A small CARMEN log: FLASER lines of 5 beams with odometry and ODOM lines, one scan every 0.5 s."""
    lines = []
    for k in range(scans):
        ranges = " ".join(f"{1.0 + 0.01 * k + 0.1 * b + shift:.3f}" for b in range(5))
        stamp = 100.0 + 0.5 * k
        lines.append(f"ODOM {0.1 * k} 0 {0.01 * k} 0 0 0 {stamp - 0.1:.6f} host {stamp - 0.1:.6f}")
        lines.append(f"FLASER 5 {ranges} {0.1 * k} 0 0 {0.1 * k} 0 {0.01 * k} {stamp:.6f} host {stamp:.6f}")
    path.write_text("\n".join(lines) + "\n")
    os.utime(path, (mtime, mtime))  # old enough for its checksum to be cached
    return path


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "decoded"
    monkeypatch.setenv("ALBOT1_DECODED_CACHE", str(folder))
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "downloads"))
    return folder


def _same(a: list[Frame], b: list[Frame]) -> None:
    assert len(a) == len(b) > 0
    for x, y in zip(a, b, strict=True):
        assert x.index == y.index
        assert x.scan.timestamp == y.scan.timestamp and x.scan.max_range == y.scan.max_range
        for p, q in ((x.scan.ranges, y.scan.ranges), (x.scan.angles, y.scan.angles), (x.odometry, y.odometry)):
            assert p.dtype == q.dtype and p.shape == q.shape and p.tobytes() == q.tobytes()
            assert p.flags.writeable == q.flags.writeable
        assert (x.reference is None) == (y.reference is None)
        if x.reference is not None and y.reference is not None:
            assert x.reference.tobytes() == y.reference.tobytes()
    # one shared read-only angle array per beam geometry, as the loader yields it (Scan.points caches on it)
    assert len({id(f.scan.angles) for f in a}) == len({id(f.scan.angles) for f in b})


def _fresh(ref: str, monkeypatch: pytest.MonkeyPatch) -> list[Frame]:
    with monkeypatch.context() as m:
        m.setenv("ALBOT1_DECODED_CACHE", "off")
        return list(open_sequence(ref))


@pytest.mark.parametrize("options", ["", "?odometry=odom", "?odometry=laser-pose&reference=laser-pose"])
def test_cached_frames_are_bit_identical_to_fresh_ones(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch, options: str
) -> None:
    log = _log(tmp_path / "a.clf", 12)
    fresh = _fresh(f"{log}{options}", monkeypatch)
    first = list(open_sequence(f"{log}{options}"))  # decoded and stored
    assert len(list(cache.glob("*.npz"))) == 1
    second = list(open_sequence(f"{log}{options}"))  # read back
    _same(fresh, first)
    _same(fresh, second)


def test_slices_and_reference_options_act_after_the_cache(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    log = _log(tmp_path / "a.clf", 20)
    list(open_sequence(str(log)))
    for ref in (f"{log}[:7]", f"{log}[::3]", f"{log}?odometry=reference&reference=laser-pose[:9:2]"):
        _same(_fresh(ref, monkeypatch), list(open_sequence(ref)))
    assert len(list(cache.glob("*.npz"))) == 2  # the raw decode of each option set, not one per slice


def test_the_key_follows_the_content_and_the_options(tmp_path: Path, cache: Path) -> None:
    log = _log(tmp_path / "a.clf", 6)
    list(open_sequence(str(log)))
    list(open_sequence(f"{log}?odometry=odom"))
    assert len(list(cache.glob("*.npz"))) == 2
    _log(log, 6, shift=0.5, mtime=1_000_000_100)  # edited: same name, new content
    after = list(open_sequence(str(log)))
    assert len(list(cache.glob("*.npz"))) == 3
    assert after[0].scan.ranges[0] == pytest.approx(1.5)


@pytest.mark.parametrize("damage", ["truncate", "garbage", "empty"])
def test_a_damaged_entry_is_rebuilt(tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch, damage: str) -> None:
    log = _log(tmp_path / "a.clf", 8)
    list(open_sequence(str(log)))
    (entry,) = cache.glob("*.npz")
    data = entry.read_bytes()
    entry.write_bytes({"truncate": data[: len(data) // 2], "garbage": b"PK\x03\x04" + b"x" * 100, "empty": b""}[damage])
    _same(_fresh(str(log), monkeypatch), list(open_sequence(str(log))))
    assert decoded.read_entry(entry) is not None  # rewritten whole


def test_an_inconsistent_entry_is_refused(tmp_path: Path, cache: Path) -> None:
    log = _log(tmp_path / "a.clf", 8)
    list(open_sequence(str(log)))
    (entry,) = cache.glob("*.npz")
    arrays = decoded.read_entry(entry)
    assert arrays is not None
    arrays["offsets"] = arrays["offsets"][:-1]
    np.savez(entry, **arrays)
    assert decoded.read_entry(entry) is None


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_cache_folder_means_decoding(tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    log = _log(tmp_path / "a.clf", 8)
    cache.mkdir()
    cache.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        _same(_fresh(str(log), monkeypatch), list(open_sequence(str(log))))
        assert not list(cache.glob("*.npz"))
    finally:
        cache.chmod(stat.S_IRWXU)


def test_an_unwritable_cache_path_means_decoding(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("ALBOT1_DECODED_CACHE", str(blocker / "decoded"))
    log = _log(tmp_path / "a.clf", 8)
    _same(_fresh(str(log), monkeypatch), list(open_sequence(str(log))))


def test_off_switches_the_cache_off(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_DECODED_CACHE", "off")
    log = _log(tmp_path / "a.clf", 4)
    sequence = open_sequence(str(log))
    list(sequence)
    assert not list(tmp_path.rglob("*.npz"))


def test_two_writers_of_one_entry_leave_a_whole_entry(tmp_path: Path, cache: Path) -> None:
    log = _log(tmp_path / "a.clf", 8)
    list(open_sequence(str(log)))
    (entry,) = cache.glob("*.npz")
    arrays = decoded.read_entry(entry)
    assert arrays is not None
    # what two cells decoding the same log at once do: each writes a whole entry and renames it into place
    assert decoded.write_entry(entry, arrays) and decoded.write_entry(entry, arrays)
    assert decoded.read_entry(entry) is not None
    assert [p.name for p in cache.iterdir()] == [entry.name]  # no temporary file left behind


def test_clear_removes_every_entry(tmp_path: Path, cache: Path) -> None:
    log = _log(tmp_path / "a.clf", 4)
    list(open_sequence(str(log)))
    assert decoded.clear() == 1
    assert not list(cache.glob("*.npz"))


def test_a_failing_write_means_decoding(tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(path: object, writer: object) -> None:
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(decoded, "atomic_write", refuse)  # a read-only folder, as seen by any user (root too)
    log = _log(tmp_path / "a.clf", 8)
    _same(_fresh(str(log), monkeypatch), list(open_sequence(str(log))))
    assert not list(cache.glob("*.npz"))
