"""The one KEY=VALUE parser (albot1.config.keyvalue): overrides and dataset reference options."""

from __future__ import annotations

import pytest

from albot1.config.keyvalue import KeyValueError, parse_key_values, parse_query
from albot1.errors import ConfigError


def test_pairs_are_split_at_the_first_equals_and_stripped() -> None:
    assert parse_key_values(["a=1", " b = x ", "url=k=v", "empty="]) == {"a": "1", "b": "x", "url": "k=v", "empty": ""}


def test_query_ignores_empty_items() -> None:
    assert parse_query("odometry=laser-pose&&max_range=80&") == {"odometry": "laser-pose", "max_range": "80"}
    assert parse_query("") == {}


@pytest.mark.parametrize(
    ("items", "message"),
    [
        (["gain"], r"^override 'gain' is not of the form FIELD=VALUE$"),
        (["=3"], r"^override '=3' is not of the form FIELD=VALUE$"),
        (["  =3"], r"^override '  =3' is not of the form FIELD=VALUE$"),
        (["a=1", "a = 2"], r"^override 'a' is given twice \('1' and '2'\); give it once$"),
    ],
)
def test_malformed_items_are_named(items: list[str], message: str) -> None:
    with pytest.raises(KeyValueError, match=message):
        parse_key_values(items, what="override", key="FIELD")


def test_the_error_is_a_config_error() -> None:
    assert issubclass(KeyValueError, ConfigError)
