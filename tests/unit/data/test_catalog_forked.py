"""The manifests parsed once for every cell (the forkserver's warm-up), listed and said again in each forked cell."""

from __future__ import annotations

import logging
import os
import shutil
from pathlib import Path

import pytest

from albot1 import resources
from albot1.data import catalog
from albot1.resources import shipped_dir


@pytest.fixture(autouse=True)
def _fresh_catalog(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(catalog, "_PARSED", {})
    monkeypatch.setattr(resources, "_said", set())
    catalog._manifests.cache_clear()
    yield
    catalog._manifests.cache_clear()


def _refuse(path: Path) -> None:
    raise AssertionError(f"{path} parsed again")


def test_warmed_manifests_are_not_parsed_again(monkeypatch: pytest.MonkeyPatch) -> None:
    catalog.warm_manifests()
    monkeypatch.setattr(catalog, "parse_manifest", _refuse)
    assert "intel" in catalog.names() and catalog.get("aces").name == "aces"


def test_warming_says_nothing_and_lists_nothing(caplog: pytest.LogCaptureFixture, tmp_path: Path) -> None:
    with caplog.at_level(logging.WARNING), pytest.MonkeyPatch.context() as patch:
        _users_aces(tmp_path, patch)
        catalog.warm_manifests()
    assert caplog.records == [] and catalog._manifests.cache_info().currsize == 0


def test_a_changed_manifest_is_parsed_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    mine = _users_aces(tmp_path, monkeypatch)
    catalog.warm_manifests()
    text = mine.read_text()
    mine.write_text(text + "\n")
    os.utime(mine, ns=(1, 1))  # another modification time, another size: another version of the file
    parsed: list[Path] = []
    original = catalog.parse_manifest
    monkeypatch.setattr(catalog, "parse_manifest", lambda p: parsed.append(p) or original(p))
    catalog.names()
    assert parsed == [mine]


def _users_aces(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A user's folder whose datasets/aces.toml replaces the project's (a copy of it)."""
    (tmp_path / "datasets").mkdir(exist_ok=True)
    mine = tmp_path / "datasets" / "aces.toml"
    shutil.copyfile(shipped_dir("datasets") / "aces.toml", mine)
    monkeypatch.setenv(resources.CONFIG_DIR_ENV, str(tmp_path))
    return mine


def _in_fork(check: object) -> int:
    """The exit code of ``check()`` (True: 0) run in a forked child, as a bench cell runs in a fork of its server."""
    pid = os.fork()
    if pid == 0:
        code = 3
        try:
            code = 0 if check() else 2  # type: ignore[operator]
        finally:
            os._exit(code)
    return os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])


def test_a_forked_cell_lists_the_manifests_again_and_says_which_a_user_replaced(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The warning goes to each cell's cell.log, as when every cell parsed the manifests itself; parsing does not."""
    mine = _users_aces(tmp_path, monkeypatch)
    catalog.warm_manifests()  # as the forkserver does
    log = tmp_path / "cell.log"

    def cell() -> bool:  # its own log file, as cell_main sets up
        logging.getLogger().addHandler(logging.FileHandler(log))
        monkeypatch.setattr(catalog, "parse_manifest", _refuse)
        return catalog.get("aces").name == "aces"  # served from the parsed memo: parse_manifest refuses

    assert _in_fork(cell) == 0
    assert f"{mine} replaces the project's" in log.read_text()


def test_a_forked_cell_with_another_config_folder_reads_its_manifests(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A server that had listed the project's manifests: a cell whose ALBOT1_CONFIG_DIR names a user's sees those."""
    assert not any(p.is_relative_to(tmp_path) for p in resources.list_resources("datasets"))
    project_aces = catalog.get("aces")
    mine = _users_aces(tmp_path, monkeypatch)
    mine.write_text(mine.read_text().replace('name = "aces"', 'name = "aces"\n# mine', 1))

    def cell() -> bool:
        return catalog.get("aces") is not project_aces and catalog.names() == sorted(catalog._manifests())

    assert _in_fork(cell) == 0
