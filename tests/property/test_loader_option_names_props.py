"""Unknown loader options: each known name listed once, a close one suggested (out49's selector sweep).

Old code: `aces-corrected?odometr=reference` read "expected some of laser, ..., reference, time_tolerance,
relations, reference, reference_max_dt, odometry=reference, views": `reference` twice, `odometry` beside
`odometry=reference`, `relations_repeats` (which every source takes) missing, and no "did you mean".
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.loaders.base import COMMON_OPTIONS
from albot1.data.loaders.carmen.options import CarmenOptions, parse_options
from albot1.data.synthetic.worlds import WorldOptionError, variant

LOG = Path("log.clf")
CARMEN_OWN = sorted(CarmenOptions.__dataclass_fields__)


def _listed(message: str) -> list[str]:
    """The names after "expected some of" in a CARMEN unknown-option error."""
    listing = message.split("expected some of ", 1)[1].split(" (did you mean", 1)[0]
    return listing.split(", ")


def test_the_carmen_listing_names_each_option_once() -> None:
    with pytest.raises(DataError) as caught:
        parse_options(LOG, {"odometr": "reference"})
    message = str(caught.value)
    names = _listed(message)
    assert len(names) == len(set(names)), names
    assert "odometry=reference" not in names and {"odometry", "reference", "relations_repeats"} <= set(names)
    assert message.endswith("(did you mean 'odometry' for 'odometr'?)")


option_name = st.from_regex(r"[a-z][a-z_]{0,14}", fullmatch=True)


@settings(max_examples=80, deadline=None)
@given(unknown=st.lists(option_name, min_size=1, max_size=3, unique=True))
def test_any_unknown_carmen_option_gets_one_line_listing_every_name_once(unknown: list[str]) -> None:
    known = set(CARMEN_OWN) | {name.partition("=")[0] for name in COMMON_OPTIONS} | {"license", "citation"}
    unknown = [name for name in unknown if name not in known]
    if not unknown:
        return
    with pytest.raises(DataError) as caught:
        parse_options(LOG, dict.fromkeys(unknown, "1"))
    message = str(caught.value)
    assert "\n" not in message and message.startswith("log.clf: unknown CARMEN loader option(s) ")
    names = _listed(message)
    assert len(names) == len(set(names)) and set(CARMEN_OWN) <= set(names)
    for name, near in re.findall(r"'([^']+)' for '([^']+)'", message):
        assert near in unknown and name in names


def test_a_world_option_typo_is_suggested() -> None:
    with pytest.raises(
        WorldOptionError, match=r"unknown loader option\(s\) lap; .*\(did you mean 'laps' for 'lap'\?\)$"
    ):
        variant("synthetic-corridor", {"lap": "2"})
