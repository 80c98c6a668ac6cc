"""What `albot1 methods --presets` shows, derived from models and presets (albot1.config.describe)."""

from __future__ import annotations

from typing import Literal

import pytest
from pydantic import BaseModel, Field

from albot1.config.describe import FieldRow, describe_presets, field_unit, type_name


@pytest.mark.parametrize(
    ("name", "unit"),
    [
        ("voxel_size_m", "m"),
        ("corner_min_angle_deg", "deg"),
        ("time_s", "s"),
        ("per_scan_ms", "ms"),
        ("memory_mb", "MiB"),
        ("min_landmarks", ""),
        ("map_every", ""),
        ("motion_model", ""),
    ],
)
def test_units_come_from_the_suffix(name: str, unit: str) -> None:
    assert field_unit(name) == unit


def test_type_names() -> None:
    assert type_name(float) == "float"
    assert type_name(Literal["thesis", "exact"]) == "thesis|exact"


class _Model(BaseModel):
    gap_m: float = Field(0.5, description="gap")
    mode: Literal["a", "b"] = "a"
    count: int


def test_fields_and_changes() -> None:
    presets = {"default": {"gap_m": 0.6, "count": 2}, "wide": {"gap_m": 1.0, "count": 2}, "same": {"gap_m": 0.6}}
    described = describe_presets(_Model, presets)
    assert described.fields == [
        FieldRow("gap_m", "float", "m", 0.6, "gap"),
        FieldRow("mode", "a|b", "", "a", ""),
        FieldRow("count", "int", "", 2, ""),
    ]
    assert described.changes == {"default": {}, "wide": {"gap_m": 1.0}, "same": {}}


def test_a_required_field_without_a_default_preset_value() -> None:
    described = describe_presets(_Model, {"default": {}})
    assert described.fields[2] == FieldRow("count", "int", "", None, "", required=True)
