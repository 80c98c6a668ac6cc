"""Stored records refuse a bool or a string where the writer always writes a number."""

import pytest
from pydantic import ValidationError

from albot1.records import Timing


def numbers() -> dict[str, object]:
    """A valid ``timing`` block: every number field 1.0 (``per_scan_reason``, text and optional, left out)."""
    return {name: 1.0 for name in Timing.model_fields if name != "per_scan_reason"}


@pytest.mark.parametrize("value", [True, "0.1"])
def test_a_bool_or_a_string_is_not_a_stored_number(value: object) -> None:
    """A hand edit of ``true`` or ``"0.1"`` was coerced to 1.0 / 0.1 and shown as a result."""
    fields = numbers()
    fields["per_scan_ms_median"] = value
    with pytest.raises(ValidationError):
        Timing.model_validate(fields)


def test_an_int_is_still_a_stored_float() -> None:
    """json.dumps may write a whole number as an int; that stays accepted for a float field."""
    fields = numbers()
    fields["per_scan_ms_median"] = 3
    assert Timing.model_validate(fields).per_scan_ms_median == 3


def test_the_valid_block_these_tests_edit_is_valid() -> None:
    """Without this, a block invalid for another reason would make the refusals above pass whatever they test."""
    assert Timing.model_validate(numbers()).per_scan_reason is None
