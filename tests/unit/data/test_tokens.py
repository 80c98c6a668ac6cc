"""The project's one number test for log fields (:func:`albot1.data.tokens.is_number`, :func:`parse_floats`):
ASCII numbers only, as numpy's bulk conversion reads them."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from albot1.data.errors import ParseError
from albot1.data.tokens import is_number, parse_floats


@pytest.mark.parametrize("token", ["1", "-0.5", "1e-3", "nan", "inf", "-inf", "+2.", ".5"])
def test_ascii_numbers_including_nan_and_inf_are_numbers(token: str) -> None:
    assert is_number(token)
    assert is_number(token.encode())


@pytest.mark.parametrize("token", ["\uff11", "\uff10.1", "\u0663", "1\u0660", "\u0967", "3_05", "x", ""])
def test_unicode_digits_and_digit_grouping_are_not_numbers(token: str) -> None:
    """``float()`` reads ``１`` and ``٣`` (and ``3_05`` as 305); numpy, and so CARMEN, refuses them."""
    assert not is_number(token)
    assert not is_number(token.encode())


def test_parse_floats_names_a_full_width_digit() -> None:
    with pytest.raises(ParseError, match=r"^f\.log:3: time: '\uff11' is not a number$"):
        parse_floats("f.log", 3, ["0.5", "\uff11"], "time:")


@given(st.text(max_size=8))
def test_is_number_is_float_on_ascii_text_without_grouping(token: str) -> None:
    try:
        float(token)
        floats = True
    except ValueError:
        floats = False
    assert is_number(token) == (floats and token.isascii() and "_" not in token)
    if is_number(token):
        assert parse_floats("f", 1, [token], "v").tolist()[0] == float(token) or math.isnan(float(token))
