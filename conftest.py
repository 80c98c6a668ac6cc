"""Fixtures shared by tests/ and benchmarks/: where the public datasets are, and skips when they are not.

Integration tests take the dataset folder from ``ALBOT1_DATA_DIR`` (set by
the Makefile and .ci/run when the shared copies exist) and skip with a reason
naming the missing file otherwise.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")


def _data_dir() -> Path | None:
    value = os.environ.get("ALBOT1_DATA_DIR")
    return Path(value) if value else None


@pytest.fixture(scope="session")
def data_file() -> Callable[[str], Path]:
    """``data_file("radish/aces.clf.bz2")`` -> the path, or skip the test with the reason."""

    def find(relative: str) -> Path:
        root = _data_dir()
        if root is None:
            pytest.skip(f"ALBOT1_DATA_DIR is not set; integration data {relative} unavailable")
        path = root / relative
        if not path.exists():
            pytest.skip(f"{path} is absent (set ALBOT1_DATA_DIR to the public dataset copies)")
        return path

    return find
