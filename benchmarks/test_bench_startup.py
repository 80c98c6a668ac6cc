"""Start-up out of the per-scan figures: the first scan of a fresh process against the median (issue 24).

Each case runs in a fresh interpreter, as a bench cell does, with numba's
cache of this code version filled (a first run fills it). The runner warms
the mapper up before its timed loop (``Mapper.warm_up``), so the first
scan should cost about what any scan that updates the map costs, not the
0.45-1.13 s of a compilation.

* ``extra_info``: ``startup_s`` (the warm-up), the runner's wall-clock
  ``first_scan_ms`` and ``median_ms``, and the same on the thread's CPU
  clock (preemption on a shared machine does not count there).
* Asserted, generously, on the CPU clock only: the first scan costs at most
  ``FACTOR`` times the median. Without the warm-up the ratio is in the
  thousands (a compile of about half a second against a 0.1 ms median).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from typing import Any

import pytest

#: "at most a few times the median": the first scan is always a map update (the median scan is not)
FACTOR = 20.0

_CODE = """
import json, sys, time
import numpy as np
from albot1.data.synthetic.worlds import load_world
from albot1.data.transforms import sensor_frame
from albot1.methods.registry import get_method, resolve_config
from albot1.runs.execute import run_method

method, preset, world = sys.argv[1:4]
result = run_method(method, load_world(world), preset=preset)
wall = result.per_scan_ns / 1e6
mapper = get_method(method).load_class()(resolve_config(method, preset, None))
mapper.warm_up()
cpu = []
for frame in sensor_frame(load_world(world)).frames():
    t0 = time.thread_time_ns()
    mapper.process(frame)
    cpu.append(time.thread_time_ns() - t0)
cpu = np.asarray(cpu) / 1e6
print(json.dumps({
    "startup_s": result.startup_s, "first_scan_ms": float(wall[0]), "median_ms": float(np.median(wall)),
    "cpu_first_scan_ms": float(cpu[0]), "cpu_median_ms": float(np.median(cpu)),
}))
"""


def _fresh(method: str, preset: str, world: str) -> dict[str, Any]:
    out = subprocess.run(
        [sys.executable, "-c", _CODE, method, preset, world],
        env=dict(os.environ),
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert out.returncode == 0, out.stderr
    found: dict[str, Any] = json.loads(out.stdout)
    return found


@pytest.mark.parametrize(("method", "preset"), [("albot1", "thesis"), ("albot1", "plus"), ("albot1-places", "default")])
def test_first_scan_of_a_fresh_process_costs_a_few_medians(benchmark: Any, method: str, preset: str) -> None:
    _fresh(method, preset, "synthetic-office-loop")  # fills numba's cache for this code version if empty
    found = benchmark.pedantic(_fresh, args=(method, preset, "synthetic-office-loop"), rounds=1, iterations=1)
    benchmark.extra_info.update(found)
    benchmark.extra_info["first_over_median_wall"] = found["first_scan_ms"] / found["median_ms"]
    benchmark.extra_info["first_over_median_cpu"] = found["cpu_first_scan_ms"] / found["cpu_median_ms"]
    assert found["cpu_first_scan_ms"] <= FACTOR * found["cpu_median_ms"], found
