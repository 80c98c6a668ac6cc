"""Fixtures shared by the data tests."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from albot1.data import catalog


@pytest.fixture
def own_project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A user's own config folder (``ALBOT1_CONFIG_DIR``, its ``datasets/`` made) and checksum cache.

    Manifests are read once per process (``catalog._manifests``): the cache is cleared on the way in and out, so
    no test sees another's datasets.
    """
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "checksum-cache"))
    (tmp_path / "project" / "datasets").mkdir(parents=True)
    monkeypatch.setenv("ALBOT1_CONFIG_DIR", str(tmp_path / "project"))
    catalog._manifests.cache_clear()
    yield tmp_path / "project"
    catalog._manifests.cache_clear()
