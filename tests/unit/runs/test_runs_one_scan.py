"""A run of one scan (`NAME[:1]`, `NAME[::5000]`, a dropout that kept only the first scan) gets no made-up scores.

The rigid alignment puts the one pose exactly on the reference's, so `albot1 evaluate` printed
"ate rmse 0.000 m" and "map_shape precision 1.000, coverage 1.000": perfect numbers that measure nothing.
They are now null with that reason; the unaligned ATE (`--trajectory ... --align none`) still measures the pose.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.data.open import open_sequence
from albot1.metrics.ate import ate
from albot1.metrics.errors import MetricsError
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

ATE_REASON = (
    "ATE: one pose, which the rigid alignment puts exactly on the reference's (its error is 0 by construction); "
    "expected at least 2 poses"
)
MAP_REASON = (
    "map shape: one scan, whose map the rigid alignment puts exactly on the reference map (agreement 1 by "
    "construction); expected at least 2 scans"
)


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "cache"))


def _run(tmp_path: Path, dataset: str) -> Path:
    return write_run(run_method("odometry", open_sequence(dataset), dataset_name=dataset), tmp_path / "runs")


def test_a_one_scan_run_has_no_ate_and_no_map_shape_with_the_reason(tmp_path: Path) -> None:
    metrics = evaluate_run(_run(tmp_path, "synthetic-office-startstop[:1]"))
    assert metrics.block("ate") is None and metrics.reason("ate") == ATE_REASON
    assert metrics.block("map_shape") is None and metrics.reason("map_shape") == MAP_REASON
    assert metrics.reason("loop_gap") == (
        "loop gap: 1 pose(s), so no route from a start to an end; expected at least 2 poses"
    )  # was "expected at least 2 poses (N, 3), got shape (1, 3)", an array's shape for a one-scan run


def test_a_two_scan_run_is_still_scored(tmp_path: Path) -> None:
    metrics = evaluate_run(_run(tmp_path, "synthetic-office-startstop[:2]"))
    assert metrics.reason("ate") is None and metrics.block("ate") is not None
    assert metrics.reason("map_shape") is None and metrics.block("map_shape") is not None


@pytest.mark.parametrize("alignment", ["rigid", "first"])
def test_one_pose_under_an_alignment_that_fits_it_is_refused(alignment: str) -> None:
    one = np.array([[1.0, 2.0, 0.3]])
    with pytest.raises(MetricsError) as caught:
        ate(one, np.zeros((1, 3)), alignment)  # type: ignore[arg-type]
    assert str(caught.value) == ATE_REASON.replace("rigid", alignment)


def test_one_pose_without_alignment_is_measured() -> None:
    block = ate(np.array([[3.0, 4.0, 0.0]]), np.zeros((1, 3)), "none")
    assert block["rmse_m"] == 5.0 and block["n"] == 1
