"""Per-scan cost of the Albot1 mapper (recorded by pytest-benchmark, never asserted).

Frames are decoded into memory first, so only ``Albot1Mapper.process`` is
timed (as the runner does, one ``perf_counter_ns`` pair per scan).
``extra_info`` holds the per-scan median/mean/p95 in ms of the measured
round; the issue's target is a median of at most 0.25 ms on the full Intel
log, and a median on a 20x longer route within 1.5x of the short one.

* ``test_albot1_intel_prefix``: first 1000 Intel scans (the CI timing).
* ``test_albot1_intel_full`` (slow): all 13,631 Intel scans, both presets.
* ``test_albot1_intel_full_cpu_time`` (slow): the same timed with the
  thread's CPU clock (wall-clock tails on a shared machine are preemption).
* ``test_albot1_route_length`` (slow): synthetic-office-loop vs the 20-lap
  synthetic-office-long; ``extra_info["median_ratio_long_vs_short"]``.
* ``test_albot1_beside_kiss_icp_intel_full`` (slow): ``thesis``, ``plus`` and
  KISS-ICP on the full Intel log in one process, per-scan time on the
  thread's CPU clock (the three run one after the other, so a loaded machine
  slows them alike); ``extra_info`` holds each one's mean, median and p95 and
  the ratios of the means to KISS-ICP's (issue 24's targets: ``thesis`` at
  most 1/5, ``plus`` at most 1/3). Means, not only medians: the median hides
  the update scans.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from albot1.data.loaders.registry import load
from albot1.data.model import Frame
from albot1.data.synthetic.worlds import load_world
from albot1.data.transforms import head
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.baselines.kiss_icp import KissIcpMapper
from albot1.methods.registry import resolve_config


def _per_scan_ns(
    frames: list[Frame], preset: str = "thesis", clock: Callable[[], int] = time.perf_counter_ns, method: str = "albot1"
) -> np.ndarray:
    # Both through resolve_config: the preset's values, with the ``ALBOT1_<METHOD>_*`` environment overrides
    # (``ALBOT1_ALBOT1_KEPT_VIEWS_TEACH=false`` measures ``plus`` without the kept views' learning).
    mapper: Any = (
        Albot1Mapper(resolve_config("albot1", preset))  # type: ignore[arg-type]
        if method == "albot1"
        else KissIcpMapper(resolve_config("kiss-icp", preset))  # type: ignore[arg-type]
    )
    out = np.empty(len(frames), dtype=np.int64)
    for i, frame in enumerate(frames):
        t0 = clock()
        mapper.process(frame)
        out[i] = clock() - t0
    mapper.finish()
    return out


def _record(benchmark: Any, ns: np.ndarray, prefix: str = "") -> None:
    ms = ns / 1e6
    benchmark.extra_info[prefix + "scans"] = int(len(ms))
    benchmark.extra_info[prefix + "per_scan_ms_median"] = float(np.median(ms))
    benchmark.extra_info[prefix + "per_scan_ms_mean"] = float(np.mean(ms))
    benchmark.extra_info[prefix + "per_scan_ms_p95"] = float(np.percentile(ms, 95))


@pytest.fixture(scope="module", autouse=True)
def _warm_kernels() -> None:
    # Compile (or load from numba's cache) before timing anything.
    Albot1Mapper(Albot1Config())
    _per_scan_ns(list(head(load_world("synthetic-office-loop"), 30)))


def test_albot1_intel_prefix(benchmark: Any, data_file: Callable[[str], Path]) -> None:
    frames = list(head(load(data_file("radish/intel.clf.bz2")), 1000))
    ns = benchmark.pedantic(_per_scan_ns, args=(frames,), rounds=3, iterations=1)
    _record(benchmark, ns)


@pytest.mark.slow
@pytest.mark.parametrize("preset", ["thesis", "exact"])
def test_albot1_intel_full(benchmark: Any, data_file: Callable[[str], Path], preset: str) -> None:
    frames = list(load(data_file("radish/intel.clf.bz2")))
    ns = benchmark.pedantic(_per_scan_ns, args=(frames, preset), rounds=1, iterations=1)
    _record(benchmark, ns)


@pytest.mark.slow
def test_albot1_intel_full_cpu_time(benchmark: Any, data_file: Callable[[str], Path]) -> None:
    """The same, timed with the thread's CPU clock: on a loaded machine wall-clock
    tails are preemption, this shows what the mapper itself costs."""
    frames = list(load(data_file("radish/intel.clf.bz2")))
    ns = benchmark.pedantic(_per_scan_ns, args=(frames, "thesis", time.thread_time_ns), rounds=1, iterations=1)
    _record(benchmark, ns)


@pytest.mark.slow
def test_albot1_route_length(benchmark: Any) -> None:
    short = list(load_world("synthetic-office-loop"))
    long = list(load_world("synthetic-office-long"))
    short_ns = _per_scan_ns(short)
    long_ns = benchmark.pedantic(_per_scan_ns, args=(long,), rounds=1, iterations=1)
    _record(benchmark, short_ns, "short_")
    _record(benchmark, long_ns, "long_")
    benchmark.extra_info["median_ratio_long_vs_short"] = float(np.median(long_ns) / np.median(short_ns))


@pytest.mark.slow
def test_albot1_beside_kiss_icp_intel_full(benchmark: Any, data_file: Callable[[str], Path]) -> None:
    frames = list(load(data_file("radish/intel.clf.bz2")))
    runs = (("kiss_icp_", "kiss-icp", "default"), ("thesis_", "albot1", "thesis"), ("plus_", "albot1", "plus"))
    for _, method, preset in runs:  # compile / load every kernel before timing
        _per_scan_ns(frames[:50], preset, time.thread_time_ns, method)
    means: dict[str, float] = {}

    def measure() -> None:
        for prefix, method, preset in runs:
            ns = _per_scan_ns(frames, preset, time.thread_time_ns, method)
            _record(benchmark, ns, prefix)
            means[prefix] = float(np.mean(ns))

    benchmark.pedantic(measure, rounds=1, iterations=1)
    for prefix in ("thesis_", "plus_"):
        benchmark.extra_info[prefix + "mean_over_kiss_icp_mean"] = means[prefix] / means["kiss_icp_"]
