"""Cost of naming data by its content (recorded by pytest-benchmark, never asserted).

* ``test_checksum_cold``: the sha256 of the Intel log read in full (what the
  first use of a file costs, once).
* ``test_checksum_warm``: :func:`albot1.data.identity.content_sha256` on the
  same file with the cache re-read from disk each round, as a new process
  does (a ``stat`` plus a small JSON read).

``extra_info["ratio"]`` is cold over warm, both measured in this one run.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from albot1.data import identity


@pytest.fixture
def aged_copy(tmp_path: Path, data_file: Callable[[str], Path], monkeypatch: pytest.MonkeyPatch) -> Path:
    """A copy of the Intel log old enough to be cached, with a private checksum cache."""
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "cache"))
    copy = tmp_path / "intel.clf.bz2"
    copy.write_bytes(data_file("radish/intel.clf.bz2").read_bytes())
    stamp = time.time() - 60
    os.utime(copy, (stamp, stamp))
    return copy


def _warm(path: Path) -> str:
    identity._CACHE._stamp = None  # re-read the cache file, as a new process would
    return identity.content_sha256(path)


def test_checksum_cold_and_warm(benchmark: Any, aged_copy: Path) -> None:
    start = time.perf_counter()
    cold_sha = identity.hash_stream(aged_copy)
    cold = time.perf_counter() - start
    assert identity.content_sha256(aged_copy) == cold_sha  # fills the cache
    assert benchmark.pedantic(_warm, args=(aged_copy,), rounds=50, iterations=1) == cold_sha
    warm = benchmark.stats.stats.median
    benchmark.extra_info.update({"cold_ms": cold * 1e3, "warm_ms": warm * 1e3, "ratio": cold / warm})
