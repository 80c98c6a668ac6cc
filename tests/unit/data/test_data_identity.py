"""Content identity of data files: sha256 cached by stat, refused special files, described content."""

from __future__ import annotations

import hashlib
import json
import os
import socket
import time
from pathlib import Path

import pytest

from albot1.data import identity
from albot1.data.errors import DataError
from albot1.data.filekind import check_input, content_kind, describe_content
from albot1.data.identity import content_sha256, short
from albot1.settings import checksum_cache_file


@pytest.fixture(autouse=True)
def private_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


def old_file(path: Path, data: bytes, age_s: float = 60.0) -> Path:
    """A file last modified ``age_s`` ago (older than the racy window, so its checksum is cached)."""
    path.write_bytes(data)
    stamp = time.time() - age_s
    os.utime(path, (stamp, stamp))
    return path


def test_a_file_checksum_is_its_sha256_and_a_warm_check_reads_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    log = old_file(tmp_path / "a.clf", b"ODOM 1 2 3\n")
    assert content_sha256(log) == hashlib.sha256(b"ODOM 1 2 3\n").hexdigest()
    assert checksum_cache_file() == tmp_path / "cache" / ".checksums.json"

    def no_read(path: Path) -> str:
        raise AssertionError(f"{path} was hashed again")

    monkeypatch.setattr(identity, "hash_stream", no_read)
    assert content_sha256(log) == hashlib.sha256(b"ODOM 1 2 3\n").hexdigest()
    assert short(content_sha256(log)) == hashlib.sha256(b"ODOM 1 2 3\n").hexdigest()[:12]


def test_a_changed_file_of_the_same_size_gets_its_new_checksum(tmp_path: Path) -> None:
    log = old_file(tmp_path / "a.clf", b"ODOM 1 2 3\n", age_s=100)
    first = content_sha256(log)
    old_file(log, b"ODOM 1 2 4\n", age_s=50)  # same size, other mtime
    assert content_sha256(log) == hashlib.sha256(b"ODOM 1 2 4\n").hexdigest() != first


def test_a_byte_flipped_behind_a_restored_modification_time_is_seen(tmp_path: Path) -> None:
    """An edit that puts the old mtime back (``touch -r``, ``rsync --times``) still changes the ctime."""
    log = old_file(tmp_path / "a.clf", b"ODOM 1 2 3\n", age_s=100)
    assert content_sha256(log) == hashlib.sha256(b"ODOM 1 2 3\n").hexdigest()
    before = log.stat()
    time.sleep(0.05)  # a ctime tick apart, whatever the file system's resolution
    with log.open("r+b") as fh:  # same size, same inode
        fh.seek(9)
        fh.write(b"4")
    os.utime(log, ns=(before.st_atime_ns, before.st_mtime_ns))
    after = log.stat()
    assert (after.st_size, after.st_mtime_ns, after.st_ino) == (before.st_size, before.st_mtime_ns, before.st_ino)
    assert content_sha256(log) == hashlib.sha256(b"ODOM 1 2 4\n").hexdigest()


def test_a_file_modified_just_now_is_not_cached(tmp_path: Path) -> None:
    log = tmp_path / "fresh.clf"
    log.write_bytes(b"x\n")
    content_sha256(log)
    cache = checksum_cache_file()
    assert not cache.exists() or str(log.resolve()) not in json.loads(cache.read_text())["files"]


@pytest.mark.parametrize("damage", ["{not json", '{"format": 3, "files": {"/x": [1, 2]}}', "[]", '{"format": 3}'])
def test_a_damaged_cache_is_ignored_and_rebuilt(tmp_path: Path, damage: str) -> None:
    log = old_file(tmp_path / "a.clf", b"abc")
    cache = checksum_cache_file()
    cache.parent.mkdir(parents=True)
    cache.write_text(damage)
    assert content_sha256(log) == hashlib.sha256(b"abc").hexdigest()
    assert json.loads(cache.read_text())["files"][str(log.resolve())][5] == hashlib.sha256(b"abc").hexdigest()


def test_a_cache_entry_with_a_wrong_checksum_for_another_stat_is_never_used(tmp_path: Path) -> None:
    log = old_file(tmp_path / "a.clf", b"abc")
    cache = checksum_cache_file()
    cache.parent.mkdir(parents=True)
    st = log.stat()
    wrong = [st.st_size, st.st_mtime_ns + 1, st.st_ctime_ns, st.st_ino, st.st_dev, "0" * 64, "x"]  # another stat
    cache.write_text(json.dumps({"format": 3, "files": {str(log.resolve()): wrong}}))
    assert content_sha256(log) == hashlib.sha256(b"abc").hexdigest()


def test_a_hand_edited_checksum_in_the_cache_is_not_trusted(tmp_path: Path) -> None:
    log = old_file(tmp_path / "a.clf", b"abc")
    content_sha256(log)
    cache = checksum_cache_file()
    data = json.loads(cache.read_text())
    data["files"][str(log.resolve())][5] = "0" * 64  # the stat still matches, the seal does not
    cache.write_text(json.dumps(data))
    assert content_sha256(log) == hashlib.sha256(b"abc").hexdigest()


@pytest.mark.timeout(30)
def test_a_cache_that_is_a_fifo_is_never_opened(tmp_path: Path) -> None:
    cache = checksum_cache_file()
    cache.parent.mkdir(parents=True)
    os.mkfifo(cache)
    log = old_file(tmp_path / "a.clf", b"abc")
    assert content_sha256(log) == hashlib.sha256(b"abc").hexdigest()


def test_a_bag_folder_is_named_by_its_files(tmp_path: Path) -> None:
    bag = tmp_path / "bag"
    bag.mkdir()
    old_file(bag / "metadata.yaml", b"m")
    old_file(bag / "bag_0.db3", b"d")
    first = content_sha256(bag)
    old_file(bag / "bag_0.db3", b"e")
    assert content_sha256(bag) != first
    with pytest.raises(DataError, match=r"bag: a folder, not a regular file; expected a data file$"):
        content_sha256(bag, folder_ok=False)


@pytest.mark.timeout(30)
def test_special_files_are_refused_by_their_stat_without_reading(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(DataError) as caught:
        content_sha256(fifo)
    assert (
        str(caught.value)
        == f"{fifo}: a FIFO (named pipe), not a regular file; expected a data file or a ROS2 bag folder"
    )
    for device in ("/dev/zero", "/dev/urandom"):
        with pytest.raises(DataError, match=rf"^{device}: a character device, not a regular file; expected x$"):
            check_input(Path(device), "x")
    with pytest.raises(DataError, match=r"^/proc/self/environ: a kernel pseudo-file .*; expected x$"):
        check_input(Path("/proc/self/environ"), "x")
    sock_path = tmp_path / "s.sock"
    with socket.socket(socket.AF_UNIX) as server:
        server.bind(str(sock_path))
        with pytest.raises(DataError, match=r"s\.sock: a socket, not a regular file; expected x$"):
            check_input(sock_path, "x")
    with pytest.raises(DataError, match=r"nothing: no such file or directory; expected x$"):
        check_input(tmp_path / "nothing", "x")
    empty = tmp_path / "empty"
    empty.write_bytes(b"")
    assert check_input(empty, "x").st_size == 0  # an empty regular file is a file (its loader says it is empty)


def test_content_is_described_by_kind_never_quoted() -> None:
    assert describe_content(b"root:x:0:0:root:/root:/bin/bash\n", lines=1) == "text, 1 line"
    assert describe_content(b"a\nb\nc", lines=3) == "text, 3 lines"
    assert describe_content(b"a\nb\n") == "text, 2 lines or more"
    assert describe_content(b"\x00\x01\x02\x03") == "binary"
    assert describe_content(b"\xff\xfe\xfa" * 10) == "binary"
    assert content_kind("grüße\n".encode()) == "text"


def test_entries_of_deleted_files_are_pruned_once_the_cache_grows(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(identity, "_PRUNE_ABOVE", 3)
    files = [old_file(tmp_path / f"f{i}", bytes([i])) for i in range(4)]
    for path in files[:3]:
        content_sha256(path)
    files[0].unlink()
    content_sha256(files[3])
    kept = json.loads(checksum_cache_file().read_text())["files"]
    assert sorted(kept) == sorted(str(p.resolve()) for p in files[1:])
