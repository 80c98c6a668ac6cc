"""Table 3.1 for a run that never moved: no bearing home is made up (out49's sweep)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.metrics.measures.orientation import ESTIMATE_AT_START, METRIC, OrientationBlock
from albot1.metrics.orientation import AT_START_M, orientation_table
from albot1.records import parse_record


def straight(n: int = 50, step: float = 0.5) -> np.ndarray:
    """A straight route along +x, facing +x, ``step`` m per pose."""
    return np.column_stack([np.arange(n) * step, np.zeros(n), np.zeros(n)])


def test_a_standing_estimate_has_no_bearing_home_on_a_straight_route() -> None:
    """Old code: atan2(0, 0) = 0 deg against the reference's 180 deg, scored as a 180 deg bearing error."""
    still = np.tile([1.0, 2.0, 0.3], (50, 1))
    table = orientation_table(still, straight())
    assert table["stops"] == 3
    assert table["bearing_undefined"] == 3
    assert table["bearing_abs_error_mean_deg"] is None and table["bearing_abs_error_max_deg"] is None
    assert all(row["estimate_bearing_deg"] is None and row["bearing_error_deg"] is None for row in table["rows"])
    # the distance error still measures the failure: the estimate says 0 m where the reference is far
    assert table["distance_abs_error_max_m"] == straight()[-1, 0]
    block = parse_record(OrientationBlock, table, "test")
    assert METRIC.headline(block) == (
        f"3 stops, bearing |err| mean n/a ({ESTIMATE_AT_START}), distance |err| mean 18.167 m"
    )
    (column,) = METRIC.columns
    assert column.applies is not None and column.applies(block, None) == ESTIMATE_AT_START  # type: ignore[arg-type]


def test_a_moving_estimate_keeps_its_bearing_and_the_column_applies() -> None:
    ref = straight()
    table = orientation_table(ref, ref)
    assert table["bearing_undefined"] == 0 and table["bearing_abs_error_max_deg"] == 0.0
    block = parse_record(OrientationBlock, table, "test")
    (column,) = METRIC.columns
    assert column.applies is not None and column.applies(block, None) is None  # type: ignore[arg-type]


def test_the_report_column_says_why(tmp_path: Path) -> None:
    from albot1.bench.grid import Cell
    from albot1.metrics.record import MetricsRecord
    from albot1.report.collect import METRIC_COLUMNS, CellRecord

    run = {"key": "k", "method": "m", "dataset": "d", "preset": "p", "degradation": "none", "seed": 0, "scans": 50}
    table = orientation_table(np.zeros((50, 3)), straight())
    metrics = parse_record(MetricsRecord, {"run": {**run, "has_reference": True}, "orientation": table}, "m")
    cell = Cell("s", "d", "d", "m", "m", "p", "none", 0, "k", "v", 1, 1)
    record = CellRecord(cell, "done", tmp_path, None, metrics, None)
    assert METRIC_COLUMNS["orientation_deg"].value(record) is None
    assert METRIC_COLUMNS["orientation_deg"].reason(record) == ESTIMATE_AT_START


coordinate = st.floats(-1e3, 1e3, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(
    start=st.tuples(coordinate, coordinate, st.floats(-np.pi, np.pi)),
    drift=st.floats(0.0, 1e-7),
    heading=st.floats(-np.pi, np.pi),
)
def test_no_bearing_error_where_the_estimate_is_on_its_start(
    start: tuple[float, float, float], drift: float, heading: float
) -> None:
    """Whatever the start and round-off, an estimate within AT_START_M of its start never gets a bearing error."""
    n = 40
    est = np.tile(np.asarray(start, dtype=float), (n, 1))
    est[1:, 0] += drift * np.cos(heading)
    est[1:, 1] += drift * np.sin(heading)
    table = orientation_table(est, straight(n))
    for row in table["rows"]:
        if row["estimate_distance_m"] < AT_START_M:
            assert row["bearing_error_deg"] is None and row["estimate_bearing_deg"] is None
    assert table["bearing_undefined"] == table["stops"]
