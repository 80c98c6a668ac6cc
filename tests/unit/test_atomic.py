"""Atomic writes leave the old file or the new one, and no temporary file."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.atomic import atomic_write, remove_temporaries


def test_replaces_and_cleans_up(tmp_path: Path) -> None:
    target = tmp_path / "a.txt"
    target.write_text("old")
    atomic_write(target, lambda p: p.write_text("new"))
    assert target.read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_failure_keeps_the_old_file(tmp_path: Path) -> None:
    target = tmp_path / "a.txt"
    target.write_text("old")

    def broken(p: Path) -> None:
        p.write_text("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        atomic_write(target, broken)
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_temporary_name_keeps_the_suffixes(tmp_path: Path) -> None:
    seen: list[str] = []
    atomic_write(tmp_path / "log.clf.gz", lambda p: (seen.append(p.name), p.write_bytes(b"x")))
    assert seen[0].endswith(".clf.gz")


def test_remove_temporaries_deletes_what_a_killed_writer_left_and_nothing_else(tmp_path: Path) -> None:
    (tmp_path / "result.json").write_text("{}")
    (tmp_path / ".hidden").write_text("keep")
    left = [tmp_path / ".result.json.abc123.tmp.json", tmp_path / ".per_scan_ns.npy.x1.tmp.npy"]
    for path in left:
        path.write_bytes(b"")
    assert sorted(p.name for p in remove_temporaries(tmp_path)) == sorted(p.name for p in left)
    assert sorted(p.name for p in tmp_path.iterdir()) == [".hidden", "result.json"]


def test_an_os_error_about_the_temporary_file_names_the_destination(tmp_path: Path) -> None:
    import errno

    def full(p: Path) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")  # what write() raises: no file name

    with pytest.raises(OSError) as caught:
        atomic_write(tmp_path / "a.txt", full)
    assert caught.value.errno == errno.ENOSPC and caught.value.filename == str(tmp_path / "a.txt")
    with pytest.raises(FileNotFoundError) as missing:
        atomic_write(tmp_path / "no-folder" / "a.txt", lambda p: p.write_text("x"))
    assert missing.value.filename == str(tmp_path / "no-folder" / "a.txt")
    assert list(tmp_path.iterdir()) == []
