"""The folders commands write into: made when missing, refused with one line when they cannot hold files."""

from __future__ import annotations

import errno
import tempfile
from pathlib import Path

import pytest

from albot1.runs.errors import OutputFolderError, RunError
from albot1.runs.output import writable_folder


def test_a_missing_folder_is_made_with_its_parents(tmp_path: Path) -> None:
    assert writable_folder(tmp_path / "a" / "b", "--out") == tmp_path / "a" / "b"
    assert (tmp_path / "a" / "b").is_dir() and not any((tmp_path / "a" / "b").iterdir())  # the probe left nothing
    assert writable_folder(tmp_path / "a" / "b", "--out").is_dir()  # an existing folder is fine


def test_a_file_is_not_a_folder(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputFolderError, match=r"^--out .*/file: is a file, not a folder; expected a folder"):
        writable_folder(tmp_path / "file", "--out")
    with pytest.raises(OutputFolderError, match=r"^--results .*/file/sub: cannot be made: .*/file is a file"):
        writable_folder(tmp_path / "file" / "sub", "--results")
    assert issubclass(OutputFolderError, RunError)


@pytest.mark.parametrize(
    ("code", "text"), [(errno.EROFS, "read-only file system"), (errno.EACCES, "permission denied")]
)
def test_a_folder_that_takes_no_file_is_refused_naming_why(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, code: int, text: str
) -> None:
    import os

    def refuse(*args: object, **kwargs: object) -> object:
        raise OSError(code, os.strerror(code), str(tmp_path))

    monkeypatch.setattr(tempfile, "TemporaryFile", refuse)
    with pytest.raises(OutputFolderError, match=rf"^--out {tmp_path}: cannot write there: {text}; expected"):
        writable_folder(tmp_path, "--out")
