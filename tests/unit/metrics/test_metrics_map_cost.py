"""Map shape, update counts and cost on inputs with exact answers."""

from __future__ import annotations

import numpy as np
import pytest

from albot1.metrics.cost import cost
from albot1.metrics.errors import MetricsError
from albot1.metrics.map_shape import map_agreement, thin
from albot1.metrics.updates import update_counts


def wall(x0: float, x1: float, y: float, spacing: float = 0.05) -> np.ndarray:
    xs = np.arange(x0, x1 + 1e-9, spacing)
    return np.column_stack([xs, np.full(len(xs), y)])


def test_identical_maps_agree_fully() -> None:
    pts = np.concatenate([wall(0, 10, 0), wall(0, 10, 3)])
    block = map_agreement(pts, pts)
    assert block["precision"] == 1.0 and block["coverage"] == 1.0
    assert block["map_to_reference_mean_m"] == pytest.approx(0.0)


def test_a_missing_wall_lowers_coverage_and_a_phantom_wall_lowers_precision() -> None:
    reference = np.concatenate([wall(0, 10, 0), wall(0, 10, 3)])
    only_one = wall(0, 10, 0)
    block = map_agreement(only_one, reference)
    assert block["precision"] == 1.0
    assert block["coverage"] == pytest.approx(0.5, abs=0.01)
    phantom = np.concatenate([reference, wall(0, 10, 6)])
    block = map_agreement(phantom, reference)
    assert block["coverage"] == 1.0
    assert block["precision"] == pytest.approx(2 / 3, abs=0.01)  # one wall in three is not there


def test_a_shifted_map_is_measured_by_its_shift() -> None:
    reference = wall(0, 10, 0)
    shifted = reference + [0.0, 0.2]
    block = map_agreement(shifted, reference)
    assert block["precision"] == 1.0  # 0.2 m < 0.3 m tolerance
    assert block["map_to_reference_median_m"] == pytest.approx(0.2, abs=1e-9)
    assert map_agreement(reference + [0.0, 0.5], reference)["precision"] == 0.0


def test_thinning_is_deterministic_and_one_point_per_cell() -> None:
    rng = np.random.default_rng(0)
    pts = rng.uniform(0, 1, size=(5000, 2))
    a, b = thin(pts, 0.1), thin(pts.copy(), 0.1)
    np.testing.assert_array_equal(a, b)
    assert len(a) == 100
    assert len(thin(pts, 0.01, max_points=300)) == 300


def test_empty_maps_are_errors_not_numbers() -> None:
    with pytest.raises(MetricsError, match="no geometry"):
        map_agreement(np.empty((0, 2)), wall(0, 1, 0))


def test_update_counts_and_baseline_counters() -> None:
    block = update_counts({"views": 1330, "updates": 470, "loop_closures": 3})
    assert block["updates_per_view"] == pytest.approx(470 / 1330)
    assert block["counters"] == {"loop_closures": 3}
    with pytest.raises(MetricsError, match="lack 'updates'"):
        update_counts({"views": 3})


def test_cost_statistics_and_growth_slope() -> None:
    per_scan_ms = np.repeat(np.arange(1.0, 11.0), 100)  # 1 ms in the first tenth ... 10 ms in the last
    block = cost(per_scan_ms * 1e6, {"total_s": 6.0, "peak_mb": 42.0})
    assert block["per_scan_ms_median"] == pytest.approx(5.5)
    assert block["per_scan_ms_p95"] == pytest.approx(10.0)
    assert block["by_position"]["per_scan_ms_median"] == pytest.approx(list(np.arange(1.0, 11.0)))
    assert block["growth_slope_ms_per_1000_scans"] == pytest.approx(10.0)  # 1 ms per 100 scans
    assert block["last_over_first_decile"] == pytest.approx(10.0)
    assert block["process_total_s"] == pytest.approx(5.5)
    assert block["peak_mb"] == 42.0
    flat = cost(np.full(1000, 2e6))
    assert flat["growth_slope_ms_per_1000_scans"] == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(MetricsError, match="no per-scan times"):
        cost(np.array([]))


def test_the_start_up_is_carried_apart_from_the_per_scan_figures() -> None:
    from albot1.metrics.measures.cost import CostBlock, headline

    per_scan_ms = np.full(100, 2.0)
    block = cost(per_scan_ms * 1e6, {"total_s": 0.2, "startup_s": 1.5})
    assert block["startup_s"] == 1.5
    assert block["per_scan_ms_mean"] == pytest.approx(2.0)  # the start-up is in no per-scan figure
    assert block["process_total_s"] == pytest.approx(0.2)
    assert headline(CostBlock.model_validate(block)).endswith("start-up 1.50 s")
    assert cost(per_scan_ms * 1e6, {})["startup_s"] is None  # a run recorded before it was measured


def test_the_kd_trees_are_built_for_speed_and_give_the_median_trees_distances(monkeypatch: pytest.MonkeyPatch) -> None:
    """Sliding-midpoint trees without shrunk nodes (session 24): every number the same as the median-split trees'."""
    from scipy.spatial import cKDTree

    from albot1.metrics import map_shape

    rng = np.random.default_rng(5)
    walls = np.concatenate([wall(0, 12, y) for y in (0.0, 2.5, 4.0)] + [wall(0, 4, 7.5, 0.02)])
    reference = walls + rng.normal(0.0, 0.03, walls.shape)
    estimate = np.concatenate([walls[::3] + (0.04, -0.02), rng.uniform(0, 12, (300, 2))])
    built: list[dict[str, object]] = []

    class Recording(cKDTree):  # type: ignore[misc]
        def __init__(self, data: np.ndarray, **options: object) -> None:
            built.append(options)
            super().__init__(data, **options)

    monkeypatch.setattr("scipy.spatial.cKDTree", Recording)
    block = map_agreement(estimate, reference)
    assert built == [map_shape.KD_TREE_OPTIONS] * 2 == [{"balanced_tree": False, "compact_nodes": False}] * 2
    mp, rp = thin(estimate), thin(reference)
    map_to_ref, ref_to_map = cKDTree(rp).query(mp)[0], cKDTree(mp).query(rp)[0]  # scipy's defaults
    assert block["precision"] == float(np.mean(map_to_ref <= 0.3))
    assert block["coverage"] == float(np.mean(ref_to_map <= 0.3))
    assert block["map_to_reference_mean_m"] == float(np.mean(map_to_ref))
    assert block["map_to_reference_median_m"] == float(np.median(map_to_ref))
    assert block["reference_to_map_mean_m"] == float(np.mean(ref_to_map))
    assert block["reference_to_map_median_m"] == float(np.median(ref_to_map))
