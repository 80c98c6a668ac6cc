"""A batch method's per-scan times are its bookkeeping, not its cost: they are recorded as not applicable.

MRPT's ``icp-slam`` and ``rbpf-slam`` run in ``finish`` over the whole log; ``process`` only keeps the frame. Their
per-scan median (0.002 ms on ``synthetic-office-loop[:300]``, against KISS-ICP's 0.6 ms) was shown in the cost
table and the runtime figure as the fastest method's, and ``albot1 evaluate`` printed it as its cost, while its
total (2.4 s) was three times KISS-ICP's (0.8 s).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict

from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame
from albot1.data.open import open_sequence
from albot1.methods import registry as methods
from albot1.methods.registry import MethodRegistry, MethodSpec
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import read_result, write_run

DATASET = "synthetic-office-loop[:12]"


class BatchConfig(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class BatchMapper:
    """Keeps the frames and does everything in ``finish``, as MRPT's wrapper does."""

    name: ClassVar[str] = "batch-fake"
    config_model: ClassVar[type[BaseModel]] = BatchConfig
    presets: ClassVar[dict[str, dict[str, Any]]] = {"default": {}}

    def __init__(self, config: BatchConfig, *, seed: int = 0) -> None:
        self.frames: list[Frame] = []

    def process(self, frame: Frame) -> None:
        self.frames.append(frame)

    def finish(self) -> MapperOutput:
        poses = np.array([f.odometry for f in self.frames], dtype=float)
        poses = poses - poses[0]  # relative to the first scan, as every method's are
        counters = {"views": len(self.frames), "updates": len(self.frames)}
        return MapperOutput(poses=poses, map=MapData(points=np.zeros((1, 2))), counters=counters)


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "cache"))


def _registry(batch: bool) -> MethodRegistry:
    return methods.method_registry().with_methods(MethodSpec("batch-fake", f"{__name__}:BatchMapper", batch=batch))


def test_the_mrpt_methods_are_declared_batch_and_the_others_are_not() -> None:
    registry = methods.method_registry()
    assert getattr(registry.get("mrpt-icp"), "batch", False)
    assert getattr(registry.get("mrpt-rbpf"), "batch", False)
    assert not any(registry.get(name).batch for name in ("odometry", "albot1", "kiss-icp", "gtsam-graph"))


def test_a_batch_run_records_no_per_scan_figures_and_says_why(tmp_path: Path) -> None:
    result = run_method("batch-fake", open_sequence(DATASET), dataset_name=DATASET, registry=_registry(True))
    timing = result.timing()
    assert (timing.per_scan_ms_median, timing.per_scan_ms_mean, timing.per_scan_ms_p95) == (None, None, None)
    assert timing.per_scan_reason is not None and "finish()" in timing.per_scan_reason
    assert len(result.per_scan_ns) == 12  # the times are still kept (per_scan_ns.npy), only not shown as cost
    run_dir = write_run(result, tmp_path / "runs")
    assert read_result(run_dir).timing.per_scan_reason == timing.per_scan_reason
    record = evaluate_run(run_dir)
    assert record.reason("cost") == f"cost: {timing.per_scan_reason}"


def test_a_run_of_a_method_working_per_scan_keeps_its_figures_and_its_file_as_before(tmp_path: Path) -> None:
    result = run_method("batch-fake", open_sequence(DATASET), dataset_name=DATASET, registry=_registry(False))
    assert result.timing().per_scan_ms_median is not None
    run_dir = write_run(result, tmp_path / "runs")
    stored = json.loads((run_dir / "result.json").read_text())
    assert "per_scan_reason" not in stored["timing"]  # written only when set: older files read and write back alike
    assert evaluate_run(run_dir).reason("cost") is None
