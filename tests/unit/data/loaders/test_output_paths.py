"""Outputs that cannot be written: one WriteError naming the path, for every writer and for convert(),
checked before the input is read; missing parent folders are created."""

from __future__ import annotations

import errno
import os
from pathlib import Path

import numpy as np
import pytest

from albot1.data.convert import convert
from albot1.data.errors import DataError, WriteError
from albot1.data.loaders import output
from albot1.data.loaders.output import check_output, writing
from albot1.data.loaders.registry import load, writer_for
from albot1.data.model import Frame, Scan, Sequence

NAMES = {"carmen": "x.clf", "albot-log": "x.albotlog", "ros1": "x.bag", "ros2-sqlite3": "x_db3", "ros2-mcap": "x_mcap"}


def sequence(n: int = 3) -> Sequence:
    angles = np.linspace(-1.0, 1.0, 11)
    frames = [Frame(i, Scan(np.full(11, 2.0), angles, 1.0 + i, 10.0), np.array([0.1 * i, 0.0, 0.0])) for i in range(n)]
    return Sequence.from_frames("out", frames)


@pytest.mark.parametrize("fmt", list(NAMES))
def test_every_writer_creates_missing_folders_and_refuses_bad_outputs(tmp_path: Path, fmt: str) -> None:
    writer = writer_for(fmt)
    deep = tmp_path / "a" / "b" / NAMES[fmt]
    writer.write(sequence(), deep)
    assert sum(1 for _ in load(deep).frames()) == 3
    with pytest.raises(WriteError, match=rf"{NAMES[fmt]} exists already"):
        writer.write(sequence(), deep)
    (tmp_path / "file").write_text("")
    with pytest.raises(WriteError, match=r"file/x.* cannot be created, .*file is a file, not a folder"):
        writer.write(sequence(), tmp_path / "file" / NAMES[fmt])


def test_check_output_names_a_read_only_or_unwritable_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(output.os, "access", lambda path, mode: False)
    monkeypatch.setattr(output, "_read_only", lambda folder: True)
    with pytest.raises(WriteError, match=rf"new/x\.clf: cannot be created in {tmp_path}: the file system is read-only"):
        check_output(tmp_path / "new" / "x.clf")
    monkeypatch.setattr(output, "_read_only", lambda folder: False)
    with pytest.raises(WriteError, match="permission denied"):
        check_output(tmp_path / "x.clf")


@pytest.mark.parametrize(
    ("code", "reason"),
    [
        (errno.EACCES, "permission denied"),
        (errno.EROFS, "the file system is read-only"),
        (errno.ENOSPC, "no space left on the device"),
        (errno.ENOTDIR, "a folder on the way is a file"),
    ],
)
def test_os_errors_while_writing_become_one_line(tmp_path: Path, code: int, reason: str) -> None:
    out = tmp_path / "x.clf"
    with pytest.raises(WriteError, match=rf"x\.clf: cannot be written: {reason}$"):
        with writing(out):
            raise OSError(code, os.strerror(code), str(tmp_path / ".x.clf.tmp"))
    with pytest.raises(DataError, match=r"in\.clf: permission denied") as info:  # the input's error keeps its name
        with writing(out):
            raise PermissionError(errno.EACCES, "Permission denied", "/elsewhere/in.clf")
    assert not isinstance(info.value, WriteError)


@pytest.mark.parametrize("fmt", list(NAMES))
def test_a_permission_error_inside_a_writer_is_a_write_error(
    tmp_path: Path, fmt: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_open = Path.open

    def refusing_open(self: Path, *args: object, **kwargs: object):  # type: ignore[no-untyped-def]
        mode = str(args[0]) if args else str(kwargs.get("mode", "r"))
        if self.parent == tmp_path and any(c in mode for c in "wxa"):
            raise PermissionError(errno.EACCES, "Permission denied", str(self))
        return real_open(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(Path, "open", refusing_open)
    import builtins

    real_builtin_open = builtins.open

    def refusing_builtin(file, mode="r", *args, **kwargs):  # type: ignore[no-untyped-def]
        if Path(str(file)).parent in (tmp_path, tmp_path / NAMES[fmt]) and any(c in mode for c in "wxa"):
            raise PermissionError(errno.EACCES, "Permission denied", str(file))
        return real_builtin_open(file, mode, *args, **kwargs)

    monkeypatch.setattr(builtins, "open", refusing_builtin)
    monkeypatch.setattr(os, "mkdir", _refuse_mkdir(tmp_path, os.mkdir))
    with pytest.raises(WriteError, match=rf"{NAMES[fmt]}: cannot be written: permission denied"):
        writer_for(fmt).write(sequence(), tmp_path / NAMES[fmt])
    assert not (tmp_path / NAMES[fmt]).exists()


def _refuse_mkdir(root: Path, real):  # type: ignore[no-untyped-def]
    def mkdir(path, *args, **kwargs):  # type: ignore[no-untyped-def]
        if Path(str(path)).parent == root:
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real(path, *args, **kwargs)

    return mkdir


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc")
def test_a_pseudo_file_system_is_refused_before_reading(tmp_path: Path) -> None:
    """/proc takes no file even for root (whom os.access lets write): refused up front, naming /proc."""
    with pytest.raises(WriteError) as info:
        check_output("/proc/x.clf")
    assert str(info.value) == (
        "/proc/x.clf: cannot be created in /proc: it is on a kernel pseudo-file system (like /proc and /sys), "
        "where no file can be created"
    )
    with pytest.raises(WriteError, match=r"^/proc/x\.clf: cannot be created in /proc: it is on a kernel"):
        convert(tmp_path / "does-not-exist.clf", "/proc/x.clf")  # the input is never opened


def test_convert_checks_the_output_before_reading_the_input(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("")
    with pytest.raises(WriteError, match="is a file, not a folder"):
        convert(tmp_path / "does-not-exist.clf", tmp_path / "file" / "out.bag")  # the input is never opened
    with pytest.raises(WriteError, match="exists already"):
        convert(tmp_path / "does-not-exist.clf", tmp_path / "file", "ros1")
