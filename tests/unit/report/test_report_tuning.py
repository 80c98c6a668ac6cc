"""Held-in marks of the reports (albot1.report.tuning) on cells of real methods and presets."""

from __future__ import annotations

from albot1.bench.grid import Cell
from albot1.report.collect import METRIC_COLUMNS
from albot1.report.tables import LEGEND, markdown
from albot1.report.tuning import MARK, dataset_name, held_in, marked, tuned_datasets


def _cell(dataset: str, method: str, preset: str = "default") -> Cell:
    return Cell(
        suite="t",
        dataset=dataset,
        dataset_label=dataset,
        method=method,
        method_label=method,
        preset=preset,
        degradation="none",
        seed=0,
        key="k",
        code_version="v",
        time_s=1.0,
        memory_mb=1.0,
    )


def test_the_dataset_of_a_reference_is_its_catalog_name() -> None:
    assert dataset_name("seattle-corrected?odometry=laser-pose[::3]") == "seattle-corrected"
    assert dataset_name("aces[:2500:2]") == "aces"
    assert dataset_name("intel-corrected?odometry=laser-pose") == "intel-corrected"
    assert dataset_name("fr079") == "fr079"


def test_cells_on_held_in_datasets_are_marked_and_held_out_ones_are_not() -> None:
    assert held_in(_cell("aces", "gtsam-graph")) is True
    assert held_in(_cell("intel-corrected?odometry=laser-pose[:500]", "gtsam-graph")) is True
    assert held_in(_cell("orebro-corrected?odometry=laser-pose", "gtsam-graph")) is True  # the switch-on check
    assert held_in(_cell("freiburg-campus-corrected?odometry=laser-pose", "gtsam-graph")) is False
    assert held_in(_cell("fhw-corrected?odometry=laser-pose", "kiss-icp")) is False
    assert held_in(_cell("intel", "kiss-icp")) is True and held_in(_cell("aces", "kiss-icp")) is False
    assert held_in(_cell("aces", "odometry")) is False  # tuned on nothing
    assert held_in(_cell("freiburg-079-corrected", "albot1", "plus")) is True
    assert held_in(_cell("freiburg-079-corrected", "albot1", "thesis")) is True  # the fr079 drive, corrected
    # a method the report cannot resolve says "unknown", not "held out"
    assert held_in(_cell("aces", "no-such-method")) is None
    assert tuned_datasets("x", "default", "albot1.no_such_module:Mapper") is None
    assert marked("0.1", True) == f"0.1 {MARK}" and marked("0.1", None) == "0.1"


def test_the_metrics_table_marks_held_in_rows_and_prints_the_legend() -> None:
    import pandas as pd  # here, not at collection: pandas costs every test run's collection

    row = {"dataset": "aces", "method": "gtsam-graph", "degradation": "none", "seeds": 1, "status": "ok"}
    row |= {"ate_rmse_m_n": 1, "ate_rmse_m_na": None}
    row |= {f"ate_rmse_m_{stat}": 0.5 for stat in ("mean", "std", "median", "min", "max")}
    table = pd.DataFrame([{**row, "held_in": True}, {**row, "method": "odometry", "held_in": False}])
    text = markdown(table, {"ate_rmse_m": METRIC_COLUMNS["ate_rmse_m"]}, "T")
    assert LEGEND in text
    assert f"| gtsam-graph {MARK} | none |" in text and "| odometry | none |" in text
