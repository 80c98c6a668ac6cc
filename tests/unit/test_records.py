"""The record models themselves: JSON conversion, strictness, dotted column paths."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from albot1.metrics.blocks import Stats
from albot1.metrics.measures.drift import DriftBlock
from albot1.metrics.record import MetricsRecord
from albot1.records import (
    AttemptRecord,
    RecordError,
    ResultRecord,
    Timing,
    check_number_path,
    dump_record,
    json_value,
    number_at,
    parse_record,
)

TIMING = {
    "per_scan_ms_median": 0.5,
    "per_scan_ms_p95": 1.0,
    "per_scan_ms_mean": 0.6,
    "finish_s": 0.1,
    "total_s": 2.0,
    "wall_s": 3.0,
    "peak_mb": 50.0,
}


def test_json_value_turns_numpy_into_python_and_non_finite_into_null() -> None:
    value = json_value(
        {1: np.int64(3), "f": np.float32(0.5), "b": np.bool_(True), "a": np.array([1.5, np.nan]), "t": (np.inf, 2)}
    )
    assert value == {"1": 3, "f": 0.5, "b": True, "a": [1.5, None], "t": [None, 2]}
    assert [type(v) for v in (value["1"], value["f"], value["b"])] == [int, float, bool]


_LEAVES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=3),
    st.floats(allow_nan=True, width=32).map(np.float32),
    st.integers(-5, 5).map(np.int64),
    st.booleans().map(np.bool_),
)
_KEYS = st.one_of(st.text(max_size=3), st.integers(-3, 3), st.booleans())


@given(
    st.recursive(
        _LEAVES,
        lambda inner: st.one_of(
            st.lists(inner, max_size=4),
            st.lists(inner, max_size=4).map(tuple),
            st.dictionaries(_KEYS, inner, max_size=4),
        ),
        max_leaves=20,
    )
)
@settings(max_examples=150, deadline=None)
def test_json_value_writes_what_json_dumps_of_the_type_by_type_walk_writes(value: object) -> None:
    """The exact-type fast path changes nothing: same JSON text (and types) as the walk by ``isinstance`` alone."""

    def walk(v: object) -> object:
        if isinstance(v, Mapping):
            return {str(k): walk(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [walk(x) for x in v]
        if isinstance(v, bool) or v is None or isinstance(v, str):
            return v
        if isinstance(v, float):
            return float(v) if math.isfinite(v) else None
        if isinstance(v, int):
            return int(v)
        return walk(v.tolist()) if callable(getattr(v, "tolist", None)) else v  # type: ignore[attr-defined]

    assert json.dumps(json_value(value)) == json.dumps(walk(value))


def test_integers_stay_integers_and_floats_stay_floats() -> None:
    # A counter written as 3 must not come back as 3.0 (the file would change).
    stats = parse_record(
        Stats, {**dict.fromkeys(("mean", "std", "median", "min", "max", "rmse"), 1.0), "n": 2, "std_ddof": 0}, "s"
    )
    assert dump_record(stats)["n"] == 2 and isinstance(dump_record(stats)["mean"], float)
    attempt = parse_record(AttemptRecord, {"elapsed_s": 1.0, "host": "h", "finished": "t"}, "a")
    assert dump_record(attempt) == {"elapsed_s": 1.0, "host": "h", "finished": "t"}


def test_an_undefined_statistic_is_null_but_a_required_number_is_never_nan() -> None:
    stats = parse_record(
        Stats, {**dict.fromkeys(("mean", "std", "median", "min", "max", "rmse"), math.nan), "n": 0, "std_ddof": 1}, "s"
    )
    assert stats.mean is None and dump_record(stats)["rmse"] is None
    # NaN becomes null on the way to JSON, so a field that must hold a number refuses it ...
    with pytest.raises(RecordError, match=r"^t: not a valid Timing: total_s: Input should be a valid number"):
        parse_record(Timing, {**TIMING, "total_s": math.nan}, "t")
    # ... and so does the model itself.
    with pytest.raises(ValidationError, match="finite number"):
        Timing(**{**TIMING, "total_s": math.nan})


def test_unknown_keys_are_refused_with_the_file_and_field() -> None:
    with pytest.raises(
        RecordError, match=r"^attempt\.json: not a valid AttemptRecord: elapsed: Extra inputs are not permitted"
    ):
        parse_record(AttemptRecord, {"elapsed_s": 1.0, "elapsed": 1.0, "host": "h", "finished": "t"}, "attempt.json")


def test_drift_headline_is_a_value_or_a_reason_and_the_reason_key_is_omitted_when_absent() -> None:
    base = {
        "alignment": "none",
        "pairs_from": "reference",
        "start_spacing_m": 1.0,
        "route_m": 5.0,
        "units": {},
        "sweep": [],
        "lengths_beyond_route_m": [10.0],
    }
    short = parse_record(DriftBlock, {**base, "at_10m": None, "at_10m_reason": "too short"}, "d")
    assert dump_record(short)["at_10m_reason"] == "too short"
    long = parse_record(DriftBlock, {**base, "at_10m": {"translation_m": 0.1, "rotation_deg": 1.0, "pairs": 3}}, "d")
    assert "at_10m_reason" not in dump_record(long)
    with pytest.raises(RecordError, match="at_10m"):
        parse_record(DriftBlock, {**base, "at_10m": None}, "d")


@pytest.mark.parametrize(
    ("model", "path"),
    [
        (MetricsRecord, "ate.rmse_m"),
        (MetricsRecord, "loop_gap.route.gap_m"),  # in both loop-gap variants
        (MetricsRecord, "loop_gap.translation_m.mean"),  # only with reference poses: a union member is enough
        (MetricsRecord, "drift.at_10m.translation_m"),
        (MetricsRecord, "updates.counters.nodes"),  # any key under a dict of numbers
        (ResultRecord, "timing.peak_mb"),
        (ResultRecord, "seed"),
    ],
)
def test_number_paths_follow_nested_models_optionals_unions_and_dicts(model: type, path: str) -> None:
    check_number_path(model, path)


@pytest.mark.parametrize(
    ("model", "path", "problem"),
    [
        (MetricsRecord, "ate.rmse", "has no field 'ate.rmse'"),
        (MetricsRecord, "atee.rmse_m", "has no field 'atee'"),
        (MetricsRecord, "loop_gap.pairs_reason", "not a number"),
        (MetricsRecord, "orientation.rows", "not a number"),
        (ResultRecord, "config.voxel_m", "not a number"),  # config values are free-form, not numbers
        (ResultRecord, "has_reference", "not a number"),  # a bool is not a table number
    ],
)
def test_number_paths_that_do_not_lead_to_a_number_are_refused(model: type, path: str, problem: str) -> None:
    with pytest.raises(KeyError, match=problem):
        check_number_path(model, path)


def test_number_at_reads_models_and_mappings() -> None:
    timing = parse_record(Timing, {**TIMING, "per_scan_ms_median": None}, "t")
    assert number_at(timing, "peak_mb") == 50.0
    assert number_at(timing, "per_scan_ms_median") is None
    assert number_at({"a": {"b": 2, "c": True, "d": "x"}}, "a.b") == 2.0
    assert number_at({"a": {"b": 2, "c": True, "d": "x"}}, "a.c") is None  # bools are not numbers
    assert number_at({"a": {"d": "x"}}, "a.d") is None and number_at(None, "a") is None
    assert number_at(timing, "per_scan_ms_median.x") is None
