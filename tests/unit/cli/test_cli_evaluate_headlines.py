"""``albot1 evaluate``'s summary: one line per metric of the registry, its own headline or its reason."""

from __future__ import annotations

import numpy as np

from albot1.cli.evaluate import headlines
from albot1.metrics.ate import ate
from albot1.metrics.loop_gap import route_gap
from albot1.metrics.measures.orientation import METRIC as ORIENTATION
from albot1.metrics.measures.orientation import OrientationBlock
from albot1.metrics.orientation import orientation_table
from albot1.metrics.record import MetricsRecord
from albot1.metrics.registry import metric_registry
from albot1.metrics.updates import update_counts
from albot1.records import parse_record

RUN = {
    "key": "k",
    "method": "m",
    "dataset": "d",
    "preset": "p",
    "degradation": "none",
    "seed": 0,
    "scans": 4,
    "has_reference": False,
}


def test_every_metric_has_a_line_in_file_order_with_its_headline_or_reason() -> None:
    poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.5, 0.0]])
    data: dict[str, object] = {"run": RUN}
    for name in metric_registry().names:
        data[name], data[f"{name}_reason"] = None, f"no {name} here"
    data["ate"], data["ate_reason"] = ate(poses, poses), None
    data["updates"], data["updates_reason"] = update_counts({"views": 4, "updates": 3, "nodes": 2}), None
    closed = {
        "units": {"gap": "m", "heading": "deg"},
        "alignment": "none (relative poses)",
        "route": route_gap(poses, None),
        "pairs": None,
        "pairs_reason": "the dataset has no reference poses",
    }
    data["loop_gap"], data["loop_gap_reason"] = closed, None
    record = parse_record(MetricsRecord, data, "test")
    assert headlines(record) == [
        "  ate          rmse 0.000 m, max 0.000 m (rigid alignment)",
        "  ate_windows  null: no ate_windows here",
        "  rpe          null: no rpe here",
        "  drift        null: no drift here",
        "  loop_gap     route gap 0.500 m",
        "  orientation  null: no orientation here",
        "  relations    null: no relations here",
        "  map_shape    null: no map_shape here",
        "  updates      3 updates / 4 views",
        "  cost         null: no cost here",
        "  places       null: no places here",
        "  relation_box null: no relation_box here",
    ]


def test_the_orientation_line_gives_the_reason_of_an_undefined_mean() -> None:
    """Old code printed "0 stops, bearing |err| mean n/a deg, distance |err| mean n/a m": n/a without a reason."""
    one = parse_record(OrientationBlock, orientation_table(np.zeros((1, 3)), np.zeros((1, 3))), "test")
    assert ORIENTATION.headline(one) == "no stop point: the run has no scan after its first"
    short = np.array([[0.0, 0.0, 0.0], [0.05, 0.0, 0.0], [0.1, 0.0, 0.0]])  # 0.1 m: the one stop is near the start
    near = parse_record(OrientationBlock, orientation_table(short, short), "test")
    assert ORIENTATION.headline(near) == (
        "1 stops, bearing |err| mean n/a (no stop point where the start's bearing is defined (none 1 m or more "
        "from the start)), distance |err| mean 0.000 m"
    )
