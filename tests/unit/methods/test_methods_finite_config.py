"""Every method's config refuses non-finite numbers (albot1.config.method_model.MethodConfig).

``--set map_voxel_m=inf`` used to run (the map collapsed to one point) and be
recorded as ``null`` in ``result.json``; each method is checked through the
same resolution ``albot1 run --set`` and a suite's ``set`` use.
"""

from __future__ import annotations

import json
import math

import pytest

from albot1.config.method_model import MethodConfig
from albot1.errors import ConfigError
from albot1.methods.registry import method_registry, resolve_config

#: Fields where ``inf`` is a meaningful setting ("no limit"), and the preset that uses it.
INF_ALLOWED = {("gtsam-graph", "odometry_trust_turn_deg"), ("gtsam-graph", "odometry_trust_run_max_turn_deg")}
#: One float field per method, as the defect report found them (kiss-icp, odometry, albot1), and one for the rest.
FLOAT_FIELD = {
    "odometry": "map_voxel_m",
    "albot1": "max_range_m",
    "albot1-places": "exit_min_width_m",
    "kiss-icp": "voxel_size_m",
    "gtsam-graph": "max_range_m",
    "mrpt-icp": "cpu_limit_s",
    "mrpt-rbpf": "cpu_limit_s",
}


def test_every_registered_method_config_is_a_method_config() -> None:
    names = [spec.name for spec in method_registry()]
    assert sorted(names) == sorted(FLOAT_FIELD)
    for spec in method_registry():
        assert issubclass(spec.load_class().config_model, MethodConfig), spec.name


@pytest.mark.parametrize("method", sorted(FLOAT_FIELD))
@pytest.mark.parametrize("value", ["inf", "-inf", "nan", "Infinity"])
def test_a_non_finite_override_is_refused_with_field_and_value(method: str, value: str) -> None:
    field = FLOAT_FIELD[method]
    with pytest.raises(ConfigError) as info:
        resolve_config(method, "default", {field: value})
    assert str(info.value) == (
        f"invalid config for method {method!r} (preset 'default'): "
        f"{field}: Input should be a finite number, found {value} (from --set)"
    )


def test_every_float_field_of_every_method_refuses_inf_unless_inf_means_no_limit() -> None:
    for spec in method_registry():
        model = spec.load_class().config_model
        for name, info in model.model_fields.items():
            if info.annotation is not float:
                continue
            if (spec.name, name) in INF_ALLOWED:
                assert resolve_config(spec.name, "default", {name: "inf"}).model_dump()[name] == math.inf
                with pytest.raises(ConfigError, match=rf"{name}: Input should be greater than 0, found nan"):
                    resolve_config(spec.name, "default", {name: "nan"})
                continue
            with pytest.raises(ConfigError, match=rf"{name}: Input should be a finite number, found inf"):
                resolve_config(spec.name, "default", {name: "inf"})


def test_the_inf_the_graph_preset_uses_stays_accepted() -> None:
    config = resolve_config("gtsam-graph", "default", {})
    assert config.model_dump()["odometry_trust_turn_deg"] == math.inf
    assert config.model_dump()["odometry_trust_run_max_turn_deg"] == math.inf


def test_a_no_limit_infinity_is_recorded_as_text_and_read_back_as_the_same_config() -> None:
    """``result.json`` used to hold ``null`` for gtsam-graph's ``inf`` ("no limit"): no config accepts that back."""
    from albot1.records import json_value

    config = resolve_config("gtsam-graph", "default")
    recorded = json.loads(json.dumps(json_value(config.model_dump(mode="json")), allow_nan=False))
    assert {field: recorded[field] for _, field in INF_ALLOWED} == dict.fromkeys((f for _, f in INF_ALLOWED), "inf")
    assert type(config).model_validate(recorded) == config
    assert config.model_dump() == type(config).model_validate(recorded).model_dump()  # floats, not text, inside
