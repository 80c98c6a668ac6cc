"""Albot1 on the public CARMEN logs (prefixes): the run completes and its counters are sane."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from albot1.data.loaders.registry import load
from albot1.data.transforms import head
from albot1.runs.execute import run_method

LOGS = ["radish/intel.clf.bz2", "radish/aces.clf.bz2", "radish/mit-csail.clf.bz2", "radish/fr079.clf.bz2"]


@pytest.mark.parametrize("log", LOGS)
def test_prefix_of_a_real_log_runs_with_sane_counters(data_file: Callable[[str], Path], log: str) -> None:
    seq = head(load(data_file(log)), 1500)
    result = run_method("albot1", seq, preset="thesis")
    c = result.counters
    assert c["views"] == 1500 and result.poses.shape == (1500, 3)
    assert np.isfinite(result.poses).all()
    assert 0.2 <= c["updates_per_view"] <= 0.9
    assert c["updates"] == c["updates_current_view"] + c["updates_previous_view"]
    assert c["map_surfaces"] == len(result.map.segments) > 0
    assert 1.0 < c["landmarks_recognised_mean"] < 10.0
    trace = result.extras["update_trace"]
    assert len(trace) == c["updates"] + 1  # plus the initial view
    assert all(t["view_scan"] in (t["scan"], t["scan"] - 1) for t in trace)


@pytest.mark.slow
@pytest.mark.whole_log
def test_full_intel_log_runs(data_file: Callable[[str], Path]) -> None:
    result = run_method("albot1", load(data_file("radish/intel.clf.bz2")), preset="exact")
    c = result.counters
    assert c["views"] == 13631
    assert 0.2 <= c["updates_per_view"] <= 0.9
    assert np.isfinite(result.poses).all()
