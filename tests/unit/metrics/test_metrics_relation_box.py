"""The relation-error box-plot metric (``relation_box``): quartiles, Tukey whiskers and outliers, exactly."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.model import Relations
from albot1.geometry import se2
from albot1.metrics.measures.relation_box import METRIC, compute, headline, quartiles
from albot1.metrics.unit import MetricInputs


def test_quartiles_whiskers_and_outliers_of_a_known_sample() -> None:
    q = quartiles(np.array([100.0, 3.0, 1.0, 4.0, 2.0]))
    # sorted 1 2 3 4 100: linear quartiles 2 and 4, IQR 2; the box reaches 4 + 1.5 * 2 = 7, so 100 is the outlier
    assert q == {
        "n": 5,
        "min": 1.0,
        "q1": 2.0,
        "median": 3.0,
        "q3": 4.0,
        "max": 100.0,
        "iqr": 2.0,
        "whisker_low": 1.0,
        "whisker_high": 4.0,
        "outliers": 1,
    }


def test_quartiles_interpolate_like_matplotlib() -> None:
    q = quartiles(np.array([0.0, 1.0, 2.0, 3.0]))
    assert (q["q1"], q["median"], q["q3"], q["outliers"]) == (0.75, 1.5, 2.25, 0)
    assert (q["whisker_low"], q["whisker_high"]) == (0.0, 3.0)


def test_an_empty_sample_has_undefined_statistics_and_no_outliers() -> None:
    q = quartiles(np.array([]))
    assert q["n"] == 0 and q["outliers"] == 0 and all(math.isnan(q[k]) for k in ("q1", "median", "iqr"))


def _inputs() -> MetricInputs:
    stamps = np.arange(21) * 2.0
    ref = np.column_stack([np.arange(21.0), np.zeros(21), np.zeros(21)])
    est = ref.copy()
    est[10:, 0] += 0.5  # a 0.5 m jump between scans 9 and 10
    pairs = [(0, 5), (8, 12), (13, 17), (2, 11), (9, 10)]
    i, j = np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])
    relations = Relations(t1=stamps[i], t2=stamps[j], poses=se2.between(ref[i], ref[j]))
    return MetricInputs(
        dataset="line",
        timestamps=stamps,
        poses=est,
        reference=ref,
        relations=relations,
        relations_source="relations.txt",
        relation_timestamps=stamps,
        relation_poses=est,
        open_dataset=lambda: pytest.fail("the relation box never opens the dataset"),
    )


def test_the_block_holds_the_distribution_of_the_relation_metrics_errors() -> None:
    block = compute(_inputs())
    # three relations span the jump (0.5 m each), two do not (0 m): sorted 0 0 0.5 0.5 0.5
    t = block.translation_m
    assert (t.n, t.min, t.q1, t.median, t.q3, t.max, t.iqr, t.outliers) == (5, 0.0, 0.0, 0.5, 0.5, 0.5, 0.5, 0)
    assert block.rotation_deg.max == pytest.approx(0.0, abs=1e-9) and block.relations_used == 5
    assert block.whisker_iqr == 1.5 and block.units == {"translation": "m", "rotation": "deg"}
    assert headline(block) == ("median 0.500 m (IQR 0.000-0.500), 0.00 deg (IQR 0.00-0.00), 0 + 0 outliers of N = 5")


def test_the_metric_needs_relations_and_says_so() -> None:
    inputs = _inputs()
    without = MetricInputs(**{**inputs.__dict__, "relations": None, "memo": {}})
    assert METRIC.missing(without) == "the dataset has no ground-truth relations"
    assert METRIC.missing(inputs) is None
