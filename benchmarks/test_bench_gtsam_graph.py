"""Timing of the gtsam-graph baseline (recorded by pytest-benchmark, never asserted).

* the whole method on the first 1000 scans of the raw Intel log (the CI
  suite stays short; the full-log number is in docs/baselines.md);
* one sequential registration (point-to-line ICP against a 10-node local
  map) and one correlative loop search, the two front-end costs per node.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from albot1.data.model import Sequence
from albot1.data.open import open_sequence
from albot1.data.transforms import head
from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph.correlative import SearchWindow, correlative_search
from albot1.methods.baselines.gtsam_graph.registration import IcpParams, Target, register
from albot1.runs.execute import run_method
from albot1.settings import get_settings

pytest.importorskip("gtsam")


@pytest.fixture(scope="module")
def intel_1000(data_file: Callable[[str], Path]) -> Sequence:
    path = data_file("radish/intel.clf.bz2")
    return head(open_sequence("intel", settings=get_settings(data_dir=path.parents[1])), 1000).materialize()


def test_bench_gtsam_graph_intel_first_1000_scans(benchmark: Any, intel_1000: Sequence) -> None:
    result = benchmark.pedantic(
        run_method, args=("gtsam-graph", intel_1000), kwargs={"dataset_name": "intel"}, rounds=1, iterations=1
    )
    ms = result.per_scan_ns / 1e6
    benchmark.extra_info.update(
        {
            "scans": len(result.poses),
            "nodes": result.counters["nodes"],
            "loop_closures_accepted": result.counters["loop_closures_accepted"],
            "per_scan_ms_median": float(np.median(ms)),
            "per_scan_ms_p95": float(np.percentile(ms, 95)),
            "total_s": result.total_s,
        }
    )
    assert len(result.poses) == 1000


def _local_map(seq: Sequence, last: int, nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """The scans at the last ``nodes`` indices before ``last`` (every 10th scan) in ``last``'s odometry frame."""
    odo = seq.odometry
    frames = list(seq.frames())
    parts = [
        se2.transform_points(se2.between(odo[last], odo[i]), frames[i].scan.points())
        for i in range(last - 10 * nodes, last, 10)
    ]
    return np.concatenate(parts), frames[last + 10].scan.points()


def test_bench_gtsam_graph_one_registration(benchmark: Any, intel_1000: Sequence) -> None:
    target_points, source = _local_map(intel_1000, 400, 10)
    target = Target.from_points(target_points)
    guess = se2.between(intel_1000.odometry[400], intel_1000.odometry[410])
    result = benchmark(register, target, source, guess, IcpParams())
    benchmark.extra_info.update(
        {"target_points": len(target), "source_points": len(source), "iterations": result.iterations}
    )


def test_bench_gtsam_graph_one_correlative_search(benchmark: Any, intel_1000: Sequence) -> None:
    target_points, source = _local_map(intel_1000, 400, 10)
    guess = se2.between(intel_1000.odometry[400], intel_1000.odometry[410])
    match = benchmark(correlative_search, target_points, source, guess, SearchWindow(half_width_m=4.0))
    benchmark.extra_info.update({"score": match.score, "ambiguity": match.ambiguity})
