"""A run with a perturbation is evaluated against its data as the run saw it (degradation and seed reopened).

``dropout:P`` leaves scans out, so a reference map built from every scan of
the log would not be the run's: map precision and coverage were "n/a" with
the false reason that the dataset changed since the run.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.data.degrade import degrade
from albot1.data.open import open_as_run, open_sequence
from albot1.geometry import se2
from albot1.metrics.alignment import rigid_transform
from albot1.metrics.map_shape import map_agreement
from albot1.metrics.unit import route_declared_closed
from albot1.runs.evaluate import evaluate_run, metric_inputs
from albot1.runs.execute import run_method
from albot1.runs.folder import read_run, write_run
from albot1.runs.scored import scored_run

WORLD = "synthetic-office-startstop[:30]"
#: every kind of degradation SPEC (albot1.data.degrade), the suite's perturbations (offset, dropout) included
PERTURBATIONS = ["thesis", "gauss:0.05:0.5", "bias:0.02:0.3", "offset:0.1:0.05:2", "dropout:0.4"]


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "cache"))


def _run(tmp_path: Path, degradation: str, seed: int = 3, dataset: str = WORLD) -> Path:
    result = run_method("odometry", open_sequence(dataset), degradation=degradation, seed=seed, dataset_name=dataset)
    return write_run(result, tmp_path / "runs")


def test_a_dropout_run_keeps_fewer_scans_than_the_log() -> None:
    kept = degrade(open_sequence(WORLD), "dropout:0.4", seed=3).arrays.timestamps
    assert 0 < len(kept) < 30  # the case the bug needs: the run's scans are not the log's


@pytest.mark.parametrize("degradation", PERTURBATIONS)
def test_the_reopened_dataset_has_the_runs_scans_for_every_perturbation(tmp_path: Path, degradation: str) -> None:
    run = read_run(_run(tmp_path, degradation))
    reopened = metric_inputs(scored_run(run)).open_dataset().arrays
    np.testing.assert_array_equal(reopened.timestamps, run.timestamps)
    assert reopened.reference is not None and run.reference is not None
    np.testing.assert_allclose(reopened.reference, run.reference, atol=1e-9)


@pytest.mark.parametrize("degradation", PERTURBATIONS)
def test_map_precision_and_coverage_are_computed_for_every_perturbation(tmp_path: Path, degradation: str) -> None:
    metrics = evaluate_run(_run(tmp_path, degradation))
    assert metrics.reason("map_shape") is None
    assert metrics.block("map_shape") is not None


def test_a_dropout_runs_map_shape_equals_the_one_computed_from_its_kept_scans(tmp_path: Path) -> None:
    run_dir = _run(tmp_path, "dropout:0.4")
    block = evaluate_run(run_dir).block("map_shape")
    assert block is not None
    # Directly: the kept scans (same SPEC and seed) projected with their reference poses and the sensor offset.
    run = read_run(run_dir)
    kept = degrade(open_sequence(WORLD), "dropout:0.4", seed=3)
    offset = np.asarray(kept.metadata.sensor_offset, dtype=float)
    cloud = np.concatenate(
        [
            se2.transform_points(se2.compose(frame.reference, offset), frame.scan.points())
            for frame in kept.frames()
            if frame.reference is not None
        ]
    )
    assert run.reference is not None
    transform = rigid_transform(run.poses, run.reference)
    expected = map_agreement(se2.transform_points(transform, run.load_map().geometry_points()), cloud)
    assert block.precision == expected["precision"]
    assert block.coverage == expected["coverage"]
    assert block.reference_points == expected["reference_points"]


def test_with_the_reference_as_odometry_a_dropout_runs_map_is_the_reference_map(tmp_path: Path) -> None:
    world = "synthetic-office-startstop[:30]?odometry=reference"
    block = evaluate_run(_run(tmp_path, "dropout:0.4", dataset=world)).block("map_shape")
    assert block is not None
    assert (block.precision, block.coverage) == (1.0, 1.0)


def test_open_as_run_applies_the_recorded_spec_and_seed() -> None:
    ran = degrade(open_sequence(WORLD), "dropout:0.4", seed=7).arrays.timestamps
    np.testing.assert_array_equal(open_as_run(WORLD, "dropout:0.4", 7).arrays.timestamps, ran)
    # no seed recorded (an external trajectory): not degraded
    np.testing.assert_array_equal(
        open_as_run(WORLD, "none", None).arrays.timestamps, open_sequence(WORLD).arrays.timestamps
    )


def test_a_closed_route_thinned_by_a_dropout_is_not_declared_closed(tmp_path: Path) -> None:
    world = "synthetic-office-startstop"
    whole = read_run(_run(tmp_path / "a", "none", dataset=world))
    assert route_declared_closed(metric_inputs(scored_run(whole)))
    thinned = read_run(_run(tmp_path / "b", "dropout:0.4", dataset=world))
    assert not route_declared_closed(metric_inputs(scored_run(thinned)))


@pytest.mark.parametrize("degradation", ["thesis", "dropout:0.4"])
def test_a_run_evaluated_with_the_sequence_it_ran_on_scores_as_when_reopened(tmp_path: Path, degradation: str) -> None:
    """``evaluate_run(opened=...)``: a bench cell's own sequence, undegraded, stands for the log reopened."""
    run_dir = _run(tmp_path, degradation)
    evaluate_run(run_dir)
    reopened = (run_dir / "metrics.json").read_bytes()
    evaluate_run(run_dir, opened=open_sequence(WORLD))
    assert (run_dir / "metrics.json").read_bytes() == reopened
    assert b'"map_shape": null' not in reopened  # the metric that reads the scans was computed


def test_a_bench_cell_opens_its_dataset_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The cell's metrics (the reference map) use the sequence the cell ran on: the log is not opened again."""
    from albot1.bench import cells
    from albot1.bench.plan import plan_suite
    from albot1.bench.suite import parse_suite
    from albot1.data import open as data_open
    from albot1.settings import get_settings

    data = {"grid": {"degradations": ["thesis"], "seeds": [0]}, "methods": [{"name": "odometry"}]}
    data["datasets"] = [{"name": WORLD, "sweep": True}]
    plan = plan_suite(parse_suite(data, name="once", source="once.toml"), get_settings())
    opened: list[str] = []

    def counting(ref: str, **options: object) -> object:
        opened.append(str(ref))
        return open_sequence(ref, **options)  # type: ignore[arg-type]

    monkeypatch.setattr(cells, "open_sequence", counting)
    monkeypatch.setattr(data_open, "open_sequence", counting)
    cell = next(c for c in plan.cells if c.degradation == "thesis")
    run_dir = cells.execute_cell(cell, tmp_path / "runs")
    assert opened.count(WORLD) == 1  # (its slice opens the whole world inside: named apart)
    assert b'"map_shape": null' not in (run_dir / "metrics.json").read_bytes()
