"""One wording of pydantic validation errors (albot1.config.validation)."""

from __future__ import annotations

import pytest
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from albot1.config.validation import describe_errors


class _Inner(BaseModel):
    count: int = Field(ge=1)


class _Outer(BaseModel):
    model_config = ConfigDict(extra="forbid")
    size_m: float = Field(gt=0)
    inner: _Inner


def _error(data: object) -> ValidationError:
    with pytest.raises(ValidationError) as info:
        _Outer.model_validate(data)
    return info.value


def test_each_problem_is_location_and_message() -> None:
    exc = _error({"size_m": -1, "inner": {"count": 0}, "colour": "red"})
    assert describe_errors(exc) == (
        "size_m: Input should be greater than 0; inner.count: Input should be greater than or equal to 1; "
        "colour: Extra inputs are not permitted"
    )


def test_sources_name_where_a_value_came_from() -> None:
    exc = _error({"size_m": "x", "inner": {"count": 1}})
    assert describe_errors(exc, {"size_m": "env ALBOT1_T_SIZE_M"}) == (
        "size_m: Input should be a valid number, unable to parse string as a number (from env ALBOT1_T_SIZE_M)"
    )


def test_top_level_problems_are_labelled() -> None:
    assert describe_errors(_error(3)).startswith("(top level): Input should be a valid dictionary")
