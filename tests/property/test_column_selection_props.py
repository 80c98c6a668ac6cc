"""``albot1 report --columns`` on arbitrary text (hypothesis): a selection of known keys or one ReportError line."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.report.collect import COST_COLUMNS, METRIC_COLUMNS
from albot1.report.column_selection import parse_columns
from albot1.report.errors import ReportError

KNOWN = {**METRIC_COLUMNS, **COST_COLUMNS}
keys = st.sampled_from(list(KNOWN))
spaces = st.text(alphabet=" \t", max_size=2)


@settings(max_examples=50, deadline=None)
@given(st.text(max_size=60) | st.lists(keys | st.text(max_size=12), max_size=6).map(",".join))
def test_any_text_is_a_selection_of_known_keys_or_one_line_naming_every_valid_key(text: str) -> None:
    try:
        picked = parse_columns(text, KNOWN)
    except ReportError as error:
        message = str(error)
        assert "\n" not in message and message.endswith(f"valid keys: {', '.join(KNOWN)}")
        return
    items = [item.strip() for item in text.split(",")]
    assert picked.keys == tuple(dict.fromkeys(items)) and set(picked.keys) <= set(KNOWN) and picked.keys


@settings(max_examples=50, deadline=None)
@given(st.lists(st.tuples(spaces, keys, spaces), min_size=1, max_size=8))
def test_known_keys_with_spaces_are_picked_once_each_in_the_order_typed(typed: list[tuple[str, str, str]]) -> None:
    picked = parse_columns(",".join(f"{before}{key}{after}" for before, key, after in typed), KNOWN)
    order = tuple(dict.fromkeys(key for _, key, _ in typed))
    assert picked.keys == order
    assert list(picked.pick(METRIC_COLUMNS)) + list(picked.pick(COST_COLUMNS)) == sorted(
        order, key=lambda key: (key in COST_COLUMNS, order.index(key))
    )
