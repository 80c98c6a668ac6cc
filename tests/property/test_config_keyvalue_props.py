"""Property tests of the KEY=VALUE parser: any text gives a dict or the documented KeyValueError."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from albot1.config.keyvalue import KeyValueError, parse_key_values, parse_query

# Keys and values as users type them: no "=" in a key, no "&" in a query item, no surrounding blanks.
KEY = st.text(st.characters(codec="utf-8", exclude_characters="=&"), min_size=1).map(str.strip).filter(bool)
VALUE = st.text(st.characters(codec="utf-8", exclude_characters="&")).map(str.strip)


@given(st.lists(st.text()))
def test_any_items_parse_or_raise_key_value_error(items: list[str]) -> None:
    try:
        out = parse_key_values(items)
    except KeyValueError:
        return
    assert len(out) == len(items)
    for item in items:
        key, _, value = item.partition("=")
        assert out[key.strip()] == value.strip()


@given(st.text())
def test_any_query_parses_or_raises_key_value_error(query: str) -> None:
    try:
        out = parse_query(query)
    except KeyValueError:
        return
    assert all(key and key == key.strip() and "&" not in key + value for key, value in out.items())


@given(st.dictionaries(KEY, VALUE))
def test_written_pairs_read_back(values: dict[str, str]) -> None:
    assert parse_key_values([f"{k}={v}" for k, v in values.items()]) == values
    assert parse_query("&".join(f"{k}={v}" for k, v in values.items())) == values
