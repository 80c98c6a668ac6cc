"""Timing of the CARMEN loader (recorded by pytest-benchmark, never asserted).

* ``test_carmen_intel_full``: the whole Intel log (13631 FLASER scans,
  2.2 MB bzip2 -> 16 MB text) decoded frame by frame -- the issue's target is
  under 1 s.
* ``test_bz2_*``: the bzip2 decompression alone, sequential vs block-parallel,
  to show how much of the total is the codec.
* ``test_carmen_intel_plain``: the same log already decompressed (parse cost only).
* ``test_carmen_aces_prefix``: per-scan cost on the first 1000 ACES scans.

``extra_info["per_scan_us"]`` is the per-scan cost of the best round.
"""

from __future__ import annotations

import bz2
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from albot1.data.loaders.carmen.bz2_parallel import iter_bz2_parallel
from albot1.data.loaders.carmen.loader import CarmenLoader


def _decode(path: Path, **options: Any) -> int:
    return sum(1 for _ in CarmenLoader().load(path, **options).frames())


def _record(benchmark: Any, scans: int) -> None:
    benchmark.extra_info["scans"] = scans
    benchmark.extra_info["per_scan_us"] = benchmark.stats.stats.min / scans * 1e6


def test_carmen_intel_full(benchmark: Any, data_file: Callable[[str], Path]) -> None:
    path = data_file("radish/intel.clf.bz2")
    scans = benchmark.pedantic(_decode, args=(path,), rounds=2, iterations=1)
    assert scans == 13631
    _record(benchmark, scans)


def test_carmen_intel_full_sequential_bz2(benchmark: Any, data_file: Callable[[str], Path]) -> None:
    path = data_file("radish/intel.clf.bz2")
    scans = benchmark.pedantic(_decode, args=(path,), kwargs={"parallel_bz2": False}, rounds=1, iterations=1)
    _record(benchmark, scans)


def test_bz2_sequential(benchmark: Any, data_file: Callable[[str], Path]) -> None:
    path = data_file("radish/intel.clf.bz2")
    benchmark.pedantic(lambda: len(bz2.open(path).read()), rounds=1, iterations=1)


def test_bz2_block_parallel(benchmark: Any, data_file: Callable[[str], Path]) -> None:
    path = data_file("radish/intel.clf.bz2")
    benchmark.pedantic(lambda: sum(len(b) for b in iter_bz2_parallel(path)), rounds=1, iterations=1)


@pytest.fixture(scope="module")
def intel_plain(data_file: Callable[[str], Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("bench_carmen") / "intel.clf"
    out.write_bytes(bz2.decompress(data_file("radish/intel.clf.bz2").read_bytes()))
    return out


def test_carmen_intel_plain(benchmark: Any, intel_plain: Path) -> None:
    scans = benchmark.pedantic(_decode, args=(intel_plain,), rounds=2, iterations=1)
    _record(benchmark, scans)


@pytest.fixture(scope="module")
def aces_prefix(data_file: Callable[[str], Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    lines = bz2.decompress(data_file("radish/aces.clf.bz2").read_bytes()).split(b"\n")
    out = tmp_path_factory.mktemp("bench_carmen") / "aces-1000.clf"
    keep, scans = [], 0
    for line in lines:
        keep.append(line)
        scans += line.startswith(b"FLASER ")
        if scans == 1000:
            break
    out.write_bytes(b"\n".join(keep) + b"\n")
    return out


def test_carmen_aces_prefix(benchmark: Any, aces_prefix: Path) -> None:
    scans = benchmark.pedantic(_decode, args=(aces_prefix,), rounds=5, iterations=1)
    assert scans == 1000
    _record(benchmark, scans)
