"""The commit a version line names: the checkout's, the one a wheel recorded at build time, or an honest unknown."""

from __future__ import annotations

import json
import subprocess
import sys
import types
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from typer.testing import CliRunner

from albot1 import versions
from albot1.cli.app import app


@pytest.fixture
def package_at(monkeypatch: pytest.MonkeyPatch) -> Iterator[Callable[[Path], None]]:
    def place(path: Path) -> None:
        path.mkdir(parents=True, exist_ok=True)
        monkeypatch.setattr(versions, "_PACKAGE_DIR", path)
        versions.git_commit.cache_clear()

    yield place
    versions.git_commit.cache_clear()


def test_the_label_never_says_none() -> None:
    assert versions.commit_label("e309a8d0c1f2") == "commit e309a8d0c1f2"
    assert versions.commit_label(None) == versions.UNKNOWN_COMMIT
    assert "None" not in versions.UNKNOWN_COMMIT and "unknown" in versions.UNKNOWN_COMMIT


def test_an_installed_package_reads_the_commit_recorded_at_build(
    tmp_path: Path, package_at: Callable[[Path], None]
) -> None:
    package = tmp_path / "site-packages" / "albot1"
    package_at(package)
    assert versions.git_commit() is None  # no checkout, no record
    (package / "_bundled").mkdir()
    (package / "_bundled" / versions.BUILD_FILE).write_text(json.dumps({"commit": "0123456789ab"}))
    versions.git_commit.cache_clear()
    assert versions.git_commit() == "0123456789ab"
    (package / "_bundled" / versions.BUILD_FILE).write_text(json.dumps({"commit": None}))
    versions.git_commit.cache_clear()
    assert versions.git_commit() is None
    (package / "_bundled" / versions.BUILD_FILE).write_text("{not json")
    versions.git_commit.cache_clear()
    assert versions.git_commit() is None


def test_a_package_inside_another_repository_does_not_take_its_commit(
    tmp_path: Path, package_at: Callable[[Path], None]
) -> None:
    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    package_at(tmp_path / "venv" / "site-packages" / "albot1")  # a virtualenv inside a clone
    assert versions.git_commit() is None


def test_a_checkout_names_its_commit(tmp_path: Path, package_at: Callable[[Path], None]) -> None:
    git = ["git", "-C", str(tmp_path), "-c", "user.name=t", "-c", "user.email=t@t"]
    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    package_at(tmp_path / "albot1")
    (tmp_path / "albot1" / "__init__.py").write_text("")
    subprocess.run([*git, "add", "-A"], check=True)
    subprocess.run([*git, "commit", "-q", "-m", "c"], check=True)
    head = subprocess.run([*git, "rev-parse", "HEAD"], check=True, capture_output=True, text=True).stdout.strip()
    assert versions.git_commit() == head[:12]
    (tmp_path / "README.md").write_text("numbers rewritten by make bench\n")  # untracked, outside the code
    versions.git_commit.cache_clear()
    assert versions.git_commit() == head[:12]
    (tmp_path / "albot1" / "__init__.py").write_text("x = 1\n")
    versions.git_commit.cache_clear()
    assert versions.git_commit() == f"{head[:12]}-dirty"
    subprocess.run([*git, "checkout", "-q", "--", "albot1"], check=True)
    (tmp_path / "albot1" / "new_module.py").write_text("")  # a module not added yet is code too
    versions.git_commit.cache_clear()
    assert versions.git_commit() == f"{head[:12]}-dirty"
    (tmp_path / "albot1" / "new_module.py").unlink()
    (tmp_path / "baselines").mkdir()
    (tmp_path / "baselines" / "odometry.toml").write_text("")  # a method's config decides its results
    versions.git_commit.cache_clear()
    assert versions.git_commit() == f"{head[:12]}-dirty"


def test_version_line_names_the_commit_or_says_it_is_unknown(
    tmp_path: Path, package_at: Callable[[Path], None]
) -> None:
    package_at(tmp_path / "albot1")  # outside git, no build record: a wheel built from a copy without a commit
    versions.code_version.cache_clear()
    try:
        result = CliRunner().invoke(app, ["--version"])
    finally:
        versions.code_version.cache_clear()
    assert result.exit_code == 0, result.output
    assert result.output.endswith(f", {versions.UNKNOWN_COMMIT})\n")
    assert "None" not in result.output


def test_the_library_versions_are_read_once_per_process_and_each_caller_gets_its_own_dict(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    calls: list[str] = []

    def version(name: str) -> str:
        calls.append(name)
        if name == "absent":
            raise versions.metadata.PackageNotFoundError(name)
        return f"{name}-1.0"

    monkeypatch.setattr(versions.metadata, "version", version)
    monkeypatch.setattr(versions, "_IMPORTED", {})
    monkeypatch.setattr(versions, "_NOT_IMPORTED", {})
    first = versions.library_versions(("numpy", "absent"))
    first["numpy"] = "changed by a caller"
    assert versions.library_versions(("numpy", "absent")) == {"numpy": "numpy-1.0", "absent": None}
    assert calls == ["numpy", "absent"]


def test_an_imported_library_keeps_the_version_it_was_imported_with_and_a_new_import_is_read_again(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A long-lived process (the bench's forkserver, its cells) records the library it runs, not a later install.

    The installed version changes under the process (an upgrade while a grid runs): a library imported when it
    was first read keeps that version; one that was not imported is read again once it is (a cell importing a
    library its forkserver had not), and kept from then on.
    """
    installed = {"kiss-icp": "1.0", "made-up-lib": "2.0"}
    monkeypatch.setattr(versions.metadata, "version", lambda name: installed[name])
    monkeypatch.setattr(versions, "_IMPORTED", {})
    monkeypatch.setattr(versions, "_NOT_IMPORTED", {})
    monkeypatch.delitem(sys.modules, "kiss_icp", raising=False)
    monkeypatch.setitem(sys.modules, "made_up_lib", types.ModuleType("made_up_lib"))  # imported
    names = ("kiss-icp", "made-up-lib")
    assert versions.library_versions(names) == {"kiss-icp": "1.0", "made-up-lib": "2.0"}
    installed.update({"kiss-icp": "1.1", "made-up-lib": "2.1"})  # both upgraded on disk meanwhile
    assert versions.library_versions(names) == {"kiss-icp": "1.0", "made-up-lib": "2.0"}  # 2.0 is what runs
    monkeypatch.setitem(sys.modules, "kiss_icp", types.ModuleType("kiss_icp"))  # now imported: the new install runs
    assert versions.library_versions(names) == {"kiss-icp": "1.1", "made-up-lib": "2.0"}
    installed["kiss-icp"] = "1.2"
    assert versions.library_versions(names) == {"kiss-icp": "1.1", "made-up-lib": "2.0"}


def test_numba_and_llvmlite_are_recorded_as_imported(monkeypatch: pytest.MonkeyPatch) -> None:
    """They compile Albot1's kernels: a run records them like numpy, the version of the module it imported."""
    import llvmlite
    import numba

    monkeypatch.setattr(versions, "_IMPORTED", {})
    monkeypatch.setattr(versions, "_NOT_IMPORTED", {})
    recorded = versions.library_versions()
    assert {"numba", "llvmlite"} <= recorded.keys()
    assert (recorded["numba"], recorded["llvmlite"]) == (numba.__version__, llvmlite.__version__)
    assert {"numba", "llvmlite"} <= versions._IMPORTED.keys()  # read while imported: kept for the process


def test_a_run_records_the_numba_that_compiled_its_kernels() -> None:
    import numba

    from albot1.data.open import open_sequence
    from albot1.runs.execute import run_method

    result = run_method("odometry", open_sequence("synthetic-office-startstop[:3]"))
    assert result.versions["numba"] == numba.__version__
    assert result.versions["llvmlite"] is not None
