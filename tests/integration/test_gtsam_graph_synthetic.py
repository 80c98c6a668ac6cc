"""gtsam-graph on the embedded office loop (exact ground truth): the loop is closed and odometry is beaten."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from albot1.data.synthetic.worlds import load_world
from albot1.metrics.ate import ate
from albot1.runs.execute import run_method

# Found, not imported, at collection (the tests import gtsam when they run).
pytestmark = pytest.mark.skipif(importlib.util.find_spec("gtsam") is None, reason="gtsam is not installed")


@pytest.mark.slow
def test_office_loop_is_closed_and_beats_odometry() -> None:
    result = run_method("gtsam-graph", load_world("synthetic-office-loop"))
    reference = result.reference
    assert reference is not None
    graph = ate(result.poses, reference)["rmse_m"]
    odometry = ate(result.odometry, reference)["rmse_m"]
    assert result.counters["loop_closures_accepted"] >= 1
    nodes = result.counters["nodes"]
    # One closure ties the return to the start (first nodes) to the last nodes.
    assert any(a < 5 and b > nodes - 15 for a, b in result.extras["loop_edges"])
    assert graph < 0.1
    assert graph < 0.25 * odometry
    # The route ends where it starts: the estimate's end gap is small, odometry's is not.
    end_gap = float(np.hypot(*(result.poses[-1, :2] - result.poses[0, :2])))
    true_gap = float(np.hypot(*(reference[-1, :2] - reference[0, :2])))
    odo_gap = float(np.hypot(*(result.odometry[-1, :2] - result.odometry[0, :2])))
    assert abs(end_gap - true_gap) < 0.1
    assert abs(odo_gap - true_gap) > 0.5
