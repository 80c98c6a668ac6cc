"""Timing of the ROS bag and albot-log loaders and writers (recorded by pytest-benchmark, never asserted).

The first 1000 scans of ACES (CARMEN, 180 beams) are converted once per
session into each format; each benchmark then streams every frame of one
file (loader: open, pose pass, decode) or writes the prefix (writer).
``extra_info["per_scan_us"]`` is the per-scan cost of the best round.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from albot1.data.convert import convert
from albot1.data.loaders.registry import load
from albot1.data.model import Sequence
from albot1.data.transforms import head

SCANS = 1000
TARGETS = {"ros1": "aces.bag", "ros2-sqlite3": "aces.db3", "ros2-mcap": "aces.mcap", "albot-log": "aces.albotlog"}


@pytest.fixture(scope="module")
def aces_prefix(data_file: Callable[[str], Path]) -> Sequence:
    return head(load(data_file("radish/aces.clf.bz2")), SCANS).materialize()


@pytest.fixture(scope="module")
def converted(aces_prefix: Sequence, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("bench_rosbag")
    return {fmt: convert(aces_prefix, root / name).output for fmt, name in TARGETS.items()}


def _count(path: Path) -> int:
    return sum(1 for _ in load(path).frames())


@pytest.mark.parametrize("fmt", list(TARGETS))
def test_bench_rosbag_load(benchmark: Any, converted: dict[str, Path], fmt: str) -> None:
    scans = benchmark.pedantic(_count, (converted[fmt],), rounds=3, iterations=1)
    benchmark.extra_info.update(format=fmt, scans=scans, per_scan_us=benchmark.stats.stats.min / scans * 1e6)
    assert scans == SCANS


@pytest.mark.parametrize("fmt", list(TARGETS))
def test_bench_rosbag_write(
    benchmark: Any, aces_prefix: Sequence, tmp_path_factory: pytest.TempPathFactory, fmt: str
) -> None:
    root = tmp_path_factory.mktemp(f"bench_write_{fmt}")
    outputs = iter(root / f"{k}_{TARGETS[fmt]}" for k in range(10))

    def write() -> int:
        return convert(aces_prefix, next(outputs)).scans

    scans = benchmark.pedantic(write, rounds=2, iterations=1)
    benchmark.extra_info.update(format=fmt, scans=scans, per_scan_us=benchmark.stats.stats.min / scans * 1e6)
    assert scans == SCANS
