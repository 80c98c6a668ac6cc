"""MRPT icp-slam on MIT CSAIL and a log with one stamp for every scan (skipped without MRPT or the data).

Target (issue 12): the end-to-start gap of the whole route is at most 3 m,
where the raw odometry's is 21.5 m. The route starts and ends at the same
place, so the gap is the accumulated error.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from albot1.data.loaders.registry import load
from albot1.data.open import open_sequence
from albot1.data.transforms import head
from albot1.geometry import se2
from albot1.runs.execute import run_method
from albot1.settings import get_settings

pytestmark = [
    pytest.mark.integration,
    pytest.mark.skipif(shutil.which("icp-slam") is None, reason="MRPT's icp-slam is not installed (make mrpt)"),
]


def _gap(poses: np.ndarray) -> float:
    return float(np.hypot(*(poses[-1, :2] - poses[0, :2])))


@pytest.mark.whole_log
def test_icp_slam_closes_mit_csail_within_3_m(data_file: Callable[[str], Path]) -> None:
    sequence = load(data_file("radish/mit-csail.clf.bz2"))
    result = run_method("mrpt-icp", sequence, dataset_name="mit-csail")
    assert result.poses.shape == (1988, 3)
    assert _gap(result.odometry) == pytest.approx(21.5, abs=0.1)
    assert _gap(result.poses) <= 3.0
    counters = result.counters
    assert counters["views"] == 1988 and 0 < counters["updates"] < 1988
    assert counters["mrpt_total_s"] > 0 and counters["mrpt_cpu_s"] > 0 and counters["map_points"] > 10_000
    assert result.extras["mrpt"]["version"] is not None
    # icp-slam is deterministic: a second run gives the same poses.
    again = run_method("mrpt-icp", sequence, dataset_name="mit-csail")
    np.testing.assert_array_equal(again.poses, result.poses)


def test_icp_slam_tracks_a_log_whose_scans_share_one_stamp(data_file: Callable[[str], Path]) -> None:
    """freiburg-campus-corrected stamps every scan 0.0: written as is, icp-slam's path froze (0.05 m for 343 m)."""
    path = data_file("radish-corrected/freiburg-campus-corrected.log.gz")
    settings = get_settings(data_dir=path.parents[1])
    seq = head(open_sequence("freiburg-campus-corrected", settings=settings, odometry="laser-pose"), 200).materialize()
    assert {frame.scan.timestamp for frame in seq.frames()} == {0.0}
    result = run_method("mrpt-icp", seq, dataset_name="freiburg-campus-corrected")
    assert result.extras["mrpt"]["rawlog_replaced_stamps"] == 199
    ratio = se2.path_length(result.poses) / se2.path_length(result.odometry)
    assert 0.9 < ratio < 1.1
