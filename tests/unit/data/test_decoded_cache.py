"""The decoded-log cache: frames read back bit-identical, keyed by content and options, damage rebuilt."""

from __future__ import annotations

import gc
import logging
import os
import stat
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest

from albot1.data import decoded
from albot1.data.model import Frame
from albot1.data.open import open_sequence


def _cache_records(caplog: pytest.LogCaptureFixture) -> list[logging.LogRecord]:
    """The decoded-log cache's own warnings (the 5-beam FLASER log's geometry warning is the loader's)."""
    return [r for r in caplog.records if r.name == "albot1.data.decoded"]


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


def _entry_of(log: Path, cache: Path) -> Path:
    from albot1.data.identity import content_sha256

    (entry,) = cache.glob(f"{content_sha256(log)}-*.npz")
    return entry


def test_an_entry_of_another_log_in_its_place_is_refused_said_and_rebuilt(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    a, b = _log(tmp_path / "a.clf", 8), _log(tmp_path / "b.clf", 8, shift=0.5)
    list(open_sequence(str(a)))
    list(open_sequence(str(b)))
    entry_a, entry_b = _entry_of(a, cache), _entry_of(b, cache)
    entry_a.write_bytes(entry_b.read_bytes())  # b's decode under a's name: it used to be read as a's frames
    with caplog.at_level("WARNING", logger="albot1.data.decoded"):
        got = list(open_sequence(str(a)))
    _same(_fresh(str(a), monkeypatch), got)
    assert got[0].scan.ranges[0] == pytest.approx(1.0)
    assert [r.getMessage() for r in _cache_records(caplog)] == [
        f"{entry_a}: decoded-log cache entry holds another key ({entry_b.stem}; expected its own name); "
        f"decoding {a} again and replacing it"
    ]
    arrays = decoded.read_entry(entry_a)
    assert arrays is not None and str(arrays["key"]) == entry_a.stem


def test_an_entry_without_a_key_is_refused(tmp_path: Path, cache: Path) -> None:
    log = _log(tmp_path / "a.clf", 8)
    list(open_sequence(str(log)))
    entry = _entry_of(log, cache)
    arrays = decoded.read_entry(entry)
    assert arrays is not None
    del arrays["key"]  # what an entry of the first layout holds
    np.savez(entry, **arrays)
    assert decoded.read_entry(entry) is None
    assert decoded.load_entry(entry) == (None, "holds another key (none; expected its own name)")


@pytest.mark.parametrize("name", ["ranges", "odometry", "stamps", "offsets"])
def test_an_entry_of_another_dtype_is_refused(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch, name: str
) -> None:
    log = _log(tmp_path / "a.clf", 8)
    list(open_sequence(str(log)))
    entry = _entry_of(log, cache)
    arrays = decoded.read_entry(entry)
    assert arrays is not None
    arrays[name] = arrays[name].astype(np.float32 if arrays[name].dtype == np.float64 else np.int32)
    np.savez(entry, **arrays)
    _same(_fresh(str(log), monkeypatch), list(open_sequence(str(log))))  # float64 again, as decoded
    np.savez(entry, **arrays)
    assert decoded.load_entry(entry) == (None, "holds arrays of other dtypes or shapes than the layout's")


def test_no_flipped_bit_of_an_entry_raises_or_reads_as_other_frames(tmp_path: Path, cache: Path) -> None:
    log = _log(tmp_path / "a.clf", 3)
    list(open_sequence(str(log)))
    entry = _entry_of(log, cache)
    good = entry.read_bytes()
    arrays = decoded.read_entry(entry)
    assert arrays is not None
    expected = [(f.scan.ranges.tobytes(), f.odometry.tobytes(), f.scan.timestamp) for f in decoded.decode(arrays)]
    # zipfile raised RuntimeError ("encrypted") and NotImplementedError (compression) for the flag and method
    # bits of the local and central headers; those, and every 16th byte elsewhere (every byte took 19 s)
    with zipfile.ZipFile(entry) as archive:
        local = [info.header_offset + k for info in archive.infolist() for k in (6, 8)]
    central = [p + k for p in range(len(good) - 4) if good[p : p + 4] == b"PK\x01\x02" for k in (8, 10)]
    assert len(local) == len(central) >= 20
    for i in sorted({*local, *central, *range(0, len(good), 16)}):
        damaged = bytearray(good)
        damaged[i] ^= 0x01
        entry.write_bytes(bytes(damaged))
        read = decoded.read_entry(entry)
        if read is not None:
            got = [(f.scan.ranges.tobytes(), f.odometry.tobytes(), f.scan.timestamp) for f in decoded.decode(read)]
            assert got == expected, f"bit 0 of byte {i} flipped"


def test_a_damaged_entry_is_said_once(tmp_path: Path, cache: Path, caplog: pytest.LogCaptureFixture) -> None:
    log = _log(tmp_path / "a.clf", 8)
    list(open_sequence(str(log)))
    entry = _entry_of(log, cache)
    entry.write_bytes(b"")
    with caplog.at_level("WARNING", logger="albot1.data.decoded"):
        list(open_sequence(str(log)))
        list(open_sequence(str(log)))  # rebuilt: read back without a word
    (record,) = _cache_records(caplog)
    assert record.getMessage().startswith(f"{entry}: decoded-log cache entry does not load (")
    assert record.getMessage().endswith(f"); decoding {log} again and replacing it")


def test_a_folder_in_place_of_an_entry_means_decoding_said(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    log = _log(tmp_path / "a.clf", 8)
    list(open_sequence(str(log)))
    entry = _entry_of(log, cache)
    entry.unlink()
    entry.mkdir()
    monkeypatch.setattr(decoded, "_warned_folders", set(), raising=False)
    with caplog.at_level("WARNING", logger="albot1.data.decoded"):
        _same(_fresh(str(log), monkeypatch), list(open_sequence(str(log))))
    assert [r.getMessage().split(";")[0] for r in _cache_records(caplog)] == [
        f"{entry}: decoded-log cache entry does not load (IsADirectoryError: Is a directory)",
        f"{entry}: cannot store the decoded log (Is a directory)",
    ]
    assert entry.is_dir()


def test_an_unwritable_folder_is_said_once(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    def refuse(path: object, writer: object) -> None:
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(decoded, "atomic_write", refuse)
    monkeypatch.setattr(decoded, "_warned_folders", set(), raising=False)
    a, b = _log(tmp_path / "a.clf", 8), _log(tmp_path / "b.clf", 8, shift=0.5)
    with caplog.at_level("WARNING", logger="albot1.data.decoded"):
        for log in (a, b, a):
            list(open_sequence(str(log)))
    (record,) = _cache_records(caplog)
    assert record.getMessage() == (
        f"{cache / _key_name(a)}: cannot store the decoded log (Permission denied); {a} is decoded on every read "
        "(point ALBOT1_DECODED_CACHE at a writable folder, or set it to off)"
    )


def _key_name(log: Path) -> str:
    from albot1.data.loaders.carmen import loader as carmen

    return f"{decoded.entry_key(log, 'carmen', carmen.__name__, {})}.npz"


def test_a_damaged_entry_is_closed_when_refused(tmp_path: Path) -> None:
    # np.load left its own handle on a zip that does not parse: freed later by the collector with a ResourceWarning
    # (a leaked descriptor per damaged entry, and a warning that failed whichever test was running then).
    entry = tmp_path / "damaged.npz"
    entry.write_bytes(b"PK\x03\x04" + b"x" * 100)  # a zip's magic, then no zip
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ResourceWarning)
        assert isinstance(decoded.load_npz(entry), str)
        gc.collect()
    assert [str(w.message) for w in caught if issubclass(w.category, ResourceWarning)] == []
