"""A number reaches a config as the user wrote it (albot1.config.resolve): ``--set`` and environment text must
be an ASCII number (pydantic alone reads ``1_0`` as 10), a suite's typed ``set`` value must have the field's type
(pydantic alone reads ``true`` as 1.0 and ``"2"`` or ``2.0`` as 2); a cross-field error names its fields' origins."""

from __future__ import annotations

import os
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st
from pydantic import BaseModel, ConfigDict, model_validator

from albot1.config.resolve import resolve
from albot1.errors import ConfigError


class _Toy(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    size_m: float = 1.0
    every: int = 1
    on: bool = True
    name: str = "a"
    low_m: float = 0.1

    @model_validator(mode="after")
    def _low_below_size(self) -> _Toy:
        if self.low_m >= self.size_m:
            raise ValueError(f"low_m ({self.low_m}) must be smaller than size_m ({self.size_m})")
        return self


PRESETS: dict[str, dict[str, Any]] = {"default": {"size_m": 2.0}}
PREFIX = "ALBOT1_TOY_"
HEAD = "invalid config for method 'toy' (preset 'default'): "


@pytest.fixture(autouse=True)
def _clean_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [n for n in os.environ if n.upper().startswith("ALBOT1_TOY")]:
        monkeypatch.delenv(name)


def _resolve(overrides: dict[str, Any], *, typed: bool = False) -> _Toy:
    return resolve(
        _Toy, PRESETS, "default", env_prefix=PREFIX, overrides=overrides, owner="toy", typed_overrides=typed
    ).config


@pytest.mark.parametrize(
    ("field", "text"), [("size_m", "1_0"), ("every", "1_0"), ("size_m", "\uff11\uff10"), ("every", "\u0663")]
)
def test_set_text_with_grouping_or_unicode_digits_is_refused(field: str, text: str) -> None:
    with pytest.raises(ConfigError) as caught:
        _resolve({field: text})
    assert str(caught.value).startswith(f"{HEAD}{field}: ")
    assert str(caught.value).endswith("(from --set)")


def test_set_text_of_grouped_digits_names_field_value_and_expectation() -> None:
    with pytest.raises(ConfigError) as caught:
        _resolve({"size_m": "1_0"})
    assert str(caught.value) == (
        f"{HEAD}size_m: found '1_0', expected a number in ASCII digits without '_' grouping (e.g. 10 or 0.5) "
        "(from --set)"
    )


def test_an_environment_variable_is_text_too(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALBOT1_TOY_EVERY", "2_0")
    with pytest.raises(ConfigError, match=r"every: found '2_0', expected a number .*\(from env ALBOT1_TOY_EVERY\)$"):
        _resolve({})


def test_plain_set_text_is_still_converted() -> None:
    assert _resolve({"size_m": "0.5", "every": "3", "on": "false", "name": "x_1", "low_m": "1e-2"}) == _Toy(
        size_m=0.5, every=3, on=False, name="x_1", low_m=0.01
    )


@given(st.floats(min_value=0.2, max_value=1e6, allow_nan=False), st.integers(min_value=-(10**9), max_value=10**9))
def test_any_number_as_python_prints_it_is_accepted(size: float, every: int) -> None:
    assert _resolve({"size_m": repr(size), "every": str(every)}) == _Toy(size_m=size, every=every)


@pytest.mark.parametrize(
    ("overrides", "problem"),
    [
        ({"size_m": True}, "size_m: found the boolean true, expected a number"),
        ({"size_m": "0.5"}, "size_m: found the string '0.5', expected a number"),
        ({"every": "2"}, "every: found the string '2', expected an integer"),
        ({"every": 2.0}, "every: found the float 2.0, expected an integer"),
        ({"every": False}, "every: found the boolean false, expected an integer"),
        ({"on": 1}, "on: found the int 1, expected a boolean (true or false)"),
        ({"on": "true"}, "on: found the string 'true', expected a boolean (true or false)"),
    ],
)
def test_typed_overrides_are_taken_as_written(overrides: dict[str, Any], problem: str) -> None:
    with pytest.raises(ConfigError) as caught:
        resolve(
            _Toy,
            PRESETS,
            "default",
            env_prefix=PREFIX,
            overrides=overrides,
            owner="toy",
            override_origin="set",
            typed_overrides=True,
        )
    assert str(caught.value) == f"{HEAD}{problem} (from set)"


def test_typed_overrides_of_the_right_type_and_ints_for_floats_pass() -> None:
    assert _resolve({"size_m": 3, "every": 2, "on": False, "name": "b"}, typed=True) == _Toy(
        size_m=3.0, every=2, on=False, name="b"
    )


def test_a_cross_field_error_names_where_its_fields_came_from() -> None:
    with pytest.raises(ConfigError) as caught:
        _resolve({"low_m": "5"})
    assert str(caught.value) == (
        f"{HEAD}(top level): Value error, low_m (5.0) must be smaller than size_m (2.0) "
        "(size_m from preset default; low_m from --set)"
    )
