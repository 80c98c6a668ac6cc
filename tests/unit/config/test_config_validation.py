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
        "size_m: Input should be greater than 0, found -1; inner.count: Input should be greater than or equal to 1, "
        "found 0; colour: Extra inputs are not permitted"
    )


def test_sources_name_where_a_value_came_from() -> None:
    exc = _error({"size_m": "x", "inner": {"count": 1}})
    assert describe_errors(exc, {"size_m": "env ALBOT1_T_SIZE_M"}) == (
        "size_m: Input should be a valid number, unable to parse string as a number, found x (from env ALBOT1_T_SIZE_M)"
    )


def test_top_level_problems_are_labelled() -> None:
    assert describe_errors(_error(3)).startswith("(top level): Input should be a valid dictionary")


@pytest.mark.parametrize(
    ("data", "expected"),
    [
        ({"size_m": [1, 2], "inner": {"count": 1}}, "size_m: Input should be a valid number, found a list of 2 items"),
        (
            {"size_m": 1, "inner": 2},
            "inner: Input should be a valid dictionary or instance of _Inner, found the integer 2",
        ),
        (
            {"size_m": 1, "inner": {"count": "x" * 50}},
            f"inner.count: Input should be a valid integer, unable to parse string as an integer, found the string "
            f"'{'x' * 40}'...",
        ),
        ({"size_m": -1, "inner": {"count": 1}}, "size_m: Input should be greater than 0, found -1"),
    ],
)
def test_found_says_what_a_value_of_the_wrong_type_was(data: object, expected: str) -> None:
    """A type error names the value with its type, a bound's error the bare value; long strings are cut."""
    described = describe_errors(_error(data), found=True)
    assert described.startswith(expected), described
    assert ("found" in described) == ("found" in expected)
    assert "x" * 41 not in described


@pytest.mark.parametrize(
    ("size", "found"),
    [
        ("0", "found 0"),
        ("-inf", "found -inf"),
        (False, "found false"),
        (None, "found null"),
        ("two metres", "found 'two metres'"),
        ("", "found ''"),
        ("x" * 70, "found '" + "x" * 60 + "...'"),
    ],
)
def test_the_value_found_is_repeated(size: object, found: str) -> None:
    message = describe_errors(_error({"size_m": size, "inner": {"count": 1}}))
    assert message.startswith("size_m: Input should be ") and message.endswith(f", {found}")


def test_a_missing_field_or_a_container_repeats_no_value() -> None:
    assert describe_errors(_error({"size_m": 1})) == "inner: Field required"
    assert describe_errors(_error({"size_m": 1, "inner": [1]})) == (
        "inner: Input should be a valid dictionary or instance of _Inner"
    )
