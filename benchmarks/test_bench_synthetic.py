"""Timing of the synthetic worlds (recorded by pytest-benchmark, never asserted).

* one 181-beam scan ray-cast in the office plan (116 walls) and in a plan
  of a few hundred walls, alone and batched over a lap of poses;
* generating each embedded world from scratch (uncached), the 37k-scan
  synthetic-office-long included: it must stay a few seconds at most;
* streaming the frames of a generated world (range noise is drawn here).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from albot1.data.synthetic import layouts, worlds
from albot1.data.synthetic.floorplan import Space, build_plan
from albot1.data.synthetic.lidar import LaserSpec, cast, cast_many
from albot1.data.synthetic.route import CONTINUOUS, sample

LASER = LaserSpec()


@pytest.fixture(scope="module")
def office() -> dict[str, Any]:
    plan = layouts.office_plan()
    return {"walls": plan.walls, "poses": sample(layouts.office_loop(), CONTINUOUS)}


@pytest.fixture(scope="module")
def cluttered() -> np.ndarray:
    """A 40 x 40 m hall with 60 seeded pillars: 244 wall segments."""
    rng = np.random.default_rng(3)
    pillars = []
    for x, y in rng.uniform(2.0, 36.0, (60, 2)):
        if abs(x - 20.0) > 1.5 or abs(y - 20.0) > 1.5:  # keep the sensor's spot free
            pillars.append((float(x), float(y), float(x) + 0.6, float(y) + 0.6))
    return build_plan("hall", [Space("hall", (0.0, 0.0, 40.0, 40.0))], obstacles=pillars).walls


def test_bench_synthetic_cast_one_scan_office(benchmark: Any, office: dict[str, Any]) -> None:
    pose = office["poses"][600]
    ranges = benchmark(cast, office["walls"], pose, LASER.angles, LASER.max_range)
    benchmark.extra_info["walls"] = len(office["walls"])
    assert ranges.shape == (181,)


def test_bench_synthetic_cast_one_scan_few_hundred_walls(benchmark: Any, cluttered: np.ndarray) -> None:
    ranges = benchmark(cast, cluttered, np.array([20.3, 20.3, 0.4]), LASER.angles, LASER.max_range)
    benchmark.extra_info["walls"] = len(cluttered)
    assert np.isfinite(ranges).all()


def test_bench_synthetic_cast_office_lap_batched(benchmark: Any, office: dict[str, Any]) -> None:
    poses = office["poses"]
    ranges = benchmark.pedantic(
        cast_many, (office["walls"], poses, LASER.angles, LASER.max_range), rounds=3, iterations=1
    )
    benchmark.extra_info["scans"] = len(poses)
    assert ranges.shape == (len(poses), 181)


@pytest.mark.parametrize("name", sorted(worlds.WORLDS))
def test_bench_synthetic_generate(benchmark: Any, name: str) -> None:
    data = benchmark.pedantic(worlds.generate, (worlds.WORLDS[name],), rounds=2, iterations=1)
    benchmark.extra_info["scans"] = data.scans
    assert data.scans > 100


def test_bench_synthetic_stream_office_loop(benchmark: Any) -> None:
    seq = worlds.load_world("synthetic-office-loop")

    def stream() -> int:
        return sum(1 for _ in seq)

    count = benchmark.pedantic(stream, rounds=3, iterations=1)
    assert count == worlds.world_data("synthetic-office-loop").scans
