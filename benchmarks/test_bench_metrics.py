"""Timing of the metrics on an ACES-sized trajectory (7374 poses, 1279 relations).

The metrics run once per run folder, so they must stay small next to the
runs themselves; these numbers show it. Inputs are generated (seeded), so the
suite needs no dataset.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from albot1.data.model import Relations
from albot1.geometry import se2
from albot1.metrics.ate import ate
from albot1.metrics.loop_gap import pair_gaps
from albot1.metrics.map_shape import map_agreement
from albot1.metrics.relations import relation_metric
from albot1.metrics.rpe import rpe_set

N = 7374


@pytest.fixture(scope="module")
def trajectories() -> dict[str, Any]:
    rng = np.random.default_rng(5)
    steps = np.column_stack([rng.uniform(0.0, 0.08, N - 1), rng.normal(0, 0.002, N - 1), rng.normal(0, 0.03, N - 1)])
    ref = se2.integrate_steps(np.zeros(3), steps)
    est = se2.integrate_steps(np.zeros(3), steps + rng.normal(0, 0.003, steps.shape))
    stamps = np.arange(N) * 0.185
    i = rng.integers(0, N - 50, 1279)
    j = i + rng.integers(1, 50, 1279)
    rel = Relations(t1=stamps[i], t2=stamps[j], poses=se2.between(ref[i], ref[j]))
    return {"ref": ref, "est": est, "stamps": stamps, "rel": rel}


def test_bench_metrics_ate(benchmark: Any, trajectories: dict[str, Any]) -> None:
    block = benchmark(ate, trajectories["est"], trajectories["ref"], "rigid")
    assert block["n"] == N


def test_bench_metrics_rpe(benchmark: Any, trajectories: dict[str, Any]) -> None:
    block = benchmark(rpe_set, trajectories["est"], trajectories["ref"])
    assert block["pairs"] == N - 1


def test_bench_metrics_relations(benchmark: Any, trajectories: dict[str, Any]) -> None:
    t = trajectories
    block = benchmark(relation_metric, t["stamps"], t["est"], t["rel"])
    assert block["translation_m"]["n"] == 1279


def test_bench_metrics_loop_pairs(benchmark: Any, trajectories: dict[str, Any]) -> None:
    t = trajectories
    block = benchmark.pedantic(pair_gaps, args=(t["stamps"], t["est"], t["ref"]), rounds=3, iterations=1)
    assert block["pairs"] >= 0


def test_bench_metrics_map_shape(benchmark: Any) -> None:
    rng = np.random.default_rng(6)
    reference = rng.uniform(-50, 50, size=(200_000, 2))
    estimate = reference[::3] + rng.normal(0, 0.05, size=(len(reference[::3]), 2))
    block = benchmark.pedantic(map_agreement, args=(estimate, reference), rounds=2, iterations=1)
    assert 0.0 <= block["precision"] <= 1.0
