"""result.json and metrics.json through their models: byte-identical round trips, not-applicable encoding."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from albot1.data.model import Frame, Relations, Scan, Sequence, SequenceMetadata
from albot1.geometry import se2
from albot1.metrics.measures.ate import AteBlock
from albot1.metrics.measures.loop_gap import ClosedRouteGapBlock, LoopGapBlock
from albot1.metrics.measures.relations import RelationsBlock
from albot1.metrics.record import MetricsRecord
from albot1.metrics.registry import metric_registry
from albot1.records import RecordError, ResultRecord, dump_record, parse_record, read_record
from albot1.runs.evaluate import METRICS_FILE, evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import RESULT_FILE, read_result, write_run

METRIC_NAMES = metric_registry().names

N = 130  # 1 m and 3 deg per scan: a 120 m circle driven about 1.1 times, 1 s per scan


def _circle(*, with_reference: bool = True, closed: bool = False) -> Sequence:
    steps = np.tile([[1.0, 0.0, np.radians(3.0)]], (N - 1, 1))
    truth = se2.integrate_steps(np.zeros(3), steps)
    odometry = se2.integrate_steps(np.zeros(3), steps * [1.0, 1.0, 1.01])  # turns over-reported by 1 %
    angles = np.linspace(-np.pi / 2, np.pi / 2, 31)
    frames = [
        Frame(i, Scan(np.full(31, 2.0), angles, 10.0 + i, 8.0), odometry[i], truth[i] if with_reference else None)
        for i in range(N)
    ]
    stamps = 10.0 + np.array([0.0, 5.0, 40.0])
    relations = Relations(stamps, stamps + [1.0, 1.0, 80.0], se2.between(truth[[0, 5, 40]], truth[[1, 6, 120]]))
    metadata = SequenceMetadata(extra={"closed_loop": True}) if closed else None
    return Sequence.from_frames("circle", frames, metadata=metadata, relations=relations)


def _assert_round_trip(path: Path, model: type[ResultRecord] | type[MetricsRecord]) -> None:
    text = path.read_text()
    assert json.dumps(dump_record(read_record(model, path)), indent=2) + "\n" == text


def test_result_and_metrics_json_round_trip_byte_for_byte(tmp_path: Path) -> None:
    run_dir = write_run(run_method("odometry", _circle(), dataset_name="in-memory-circle"), tmp_path)
    metrics = evaluate_run(run_dir)
    _assert_round_trip(run_dir / RESULT_FILE, ResultRecord)
    _assert_round_trip(run_dir / METRICS_FILE, MetricsRecord)
    assert read_record(MetricsRecord, run_dir / METRICS_FILE) == metrics
    result = read_result(run_dir)
    assert (result.method, result.dataset, result.scans, result.relations, result.map_file) == (
        "odometry",
        "in-memory-circle",
        N,
        3,
        "map.npz",
    )
    assert result.counters["views"] == N and isinstance(result.counters["views"], int)
    # Every kind of block this run can have was computed and typed.
    assert isinstance(metrics.ate, AteBlock) and metrics.ate.n == N
    assert isinstance(metrics.loop_gap, LoopGapBlock) and metrics.loop_gap.pairs > 0
    assert isinstance(metrics.relations, RelationsBlock) and metrics.relations.relations_used == 3
    assert metrics.ate_windows is not None and metrics.drift is not None and metrics.orientation is not None
    assert metrics.rpe is not None and metrics.rpe.delta == 1 and isinstance(metrics.rpe.delta, int)


def test_a_metric_that_does_not_apply_is_null_with_a_reason_and_a_computed_one_has_no_reason_key(
    tmp_path: Path,
) -> None:
    run_dir = write_run(run_method("odometry", _circle(with_reference=False), dataset_name="in-memory-x"), tmp_path)
    record = evaluate_run(run_dir)
    data = json.loads((run_dir / METRICS_FILE).read_text())
    for name in METRIC_NAMES:
        computed = record.block(name) is not None
        assert (data[name] is not None) == computed and (f"{name}_reason" in data) == (not computed), name
    assert record.ate is None and record.reason("ate") == "the dataset has no reference poses"
    assert record.map_shape is None and record.reason("map_shape") == "the dataset has no reference poses"
    assert record.relations is not None and record.reason("relations") is None  # relations need no reference poses
    _assert_round_trip(run_dir / METRICS_FILE, MetricsRecord)


def test_a_closed_route_without_reference_round_trips_with_its_pairs_reason(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    closed = _circle(with_reference=False, closed=True)
    run_dir = write_run(run_method("odometry", closed, dataset_name="ring"), tmp_path)
    monkeypatch.setattr("albot1.runs.evaluate.open_as_run", lambda ref, *_, **__: closed)
    block = evaluate_run(run_dir).loop_gap
    assert isinstance(block, ClosedRouteGapBlock)
    assert block.pairs is None and block.pairs_reason == "the dataset has no reference poses"
    assert json.loads((run_dir / METRICS_FILE).read_text())["loop_gap"]["pairs"] is None
    _assert_round_trip(run_dir / METRICS_FILE, MetricsRecord)


def test_a_hand_edited_result_json_is_one_clear_error(tmp_path: Path) -> None:
    run_dir = write_run(run_method("odometry", _circle(), dataset_name="in-memory-circle"), tmp_path)
    data = json.loads((run_dir / RESULT_FILE).read_text())
    data["timing"]["per_scan_ms_medain"] = data["timing"].pop("per_scan_ms_median")
    (run_dir / RESULT_FILE).write_text(json.dumps(data))
    with pytest.raises(RecordError) as err:
        read_result(run_dir)
    message = str(err.value)
    assert message.startswith(f"{run_dir / RESULT_FILE}: not a valid ResultRecord: timing.per_scan_ms_median: Field")
    assert "timing.per_scan_ms_medain: Extra inputs are not permitted" in message and "\n" not in message


def test_metrics_need_a_block_or_a_reason_never_both() -> None:
    data = json.loads(json.dumps({"run": {}, **{name: None for name in METRIC_NAMES}}))
    with pytest.raises(RecordError, match="run.key: Field required"):
        parse_record(MetricsRecord, data, "m.json")
    run = {
        "key": "k",
        "method": "m",
        "dataset": "d",
        "preset": "p",
        "degradation": "none",
        "seed": 0,
        "scans": 1,
        "has_reference": False,
    }
    reasons = {f"{name}_reason": "absent" for name in METRIC_NAMES}
    record = parse_record(MetricsRecord, {"run": run, **reasons}, "m.json")
    assert all(record.block(name) is None for name in METRIC_NAMES)
    with pytest.raises(RecordError, match="metric 'ate' has neither a block nor a reason"):
        parse_record(MetricsRecord, {"run": run, **reasons, "ate_reason": None}, "m.json")
    updates = {"units": "counts", "views": 2, "updates": 1, "updates_per_view": 0.5, "counters": {}}
    with pytest.raises(RecordError, match="metric 'updates' has both a block and a reason"):
        parse_record(MetricsRecord, {"run": run, **reasons, "updates": updates}, "m.json")
