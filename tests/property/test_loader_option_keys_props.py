"""Any ``?key=value`` is an option or one line, never a TypeError of the opening code (out49's selector sweep).

Old code: `?settings=1`, `?path=1`, `?manifest_relations=1` (any source) and `?name=x` (a registered dataset)
reached Python calls that take a parameter of that name: "open_sequence() got multiple values for keyword
argument 'settings'", a traceback. The keys tried include every parameter name of the functions a reference
passes through, read from their signatures, so a parameter added later is tried too.
"""

from __future__ import annotations

import inspect
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from albot1.data import catalog
from albot1.data import open as data_open
from albot1.data.convert import convert
from albot1.data.errors import DataError
from albot1.data.loaders import registry
from albot1.data.loaders.albot_log.loader import AlbotLogLoader
from albot1.data.loaders.carmen.loader import CarmenLoader
from albot1.data.synthetic import worlds
from albot1.settings import Settings

WORLD = "synthetic-square-startstop"
FUNCTIONS = (
    data_open.open_sequence,
    data_open._open_source,
    data_open._with_own_files,
    data_open._with_reference_options,
    catalog.open_dataset,
    registry.load,
    worlds.load_world,
    worlds.world_data,
    CarmenLoader.load,
    AlbotLogLoader.load,
)
PARAMETERS = sorted({name for f in FUNCTIONS for name in inspect.signature(f).parameters} - {"options"})


@pytest.fixture(scope="module")
def sources(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    folder = tmp_path_factory.mktemp("keys")
    convert(f"{WORLD}[:5]", folder / "w.clf", "carmen")
    convert(f"{WORLD}[:5]", folder / "w.albot", "albot-log")
    return [WORLD, str(folder / "w.clf"), str(folder / "w.albot")]


def test_the_parameter_names_are_found() -> None:
    assert {"settings", "format_name", "manifest_relations", "path", "name"} <= set(PARAMETERS)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(key=st.one_of(st.sampled_from(PARAMETERS), st.from_regex(r"[a-z][a-z_]{0,11}", fullmatch=True)))
def test_any_key_opens_or_is_one_line(sources: list[str], key: str) -> None:
    cache = Path(sources[1]).parent / "cache"
    for source in sources:
        try:
            data_open.open_sequence(f"{source}?{key}=1[:2]", settings=Settings(data_dir=None, cache_dir=cache))
        except DataError as exc:
            assert "\n" not in str(exc) and "got multiple values" not in str(exc)


@pytest.mark.parametrize("key", ["name", "settings", "manifest_relations", "path"])
def test_a_registered_dataset_refuses_them_in_one_line(data_file, key: str) -> None:  # type: ignore[no-untyped-def]
    """`aces-corrected?name=x` was "open_dataset() got multiple values for argument 'name'"."""
    data_file("radish-corrected/aces-corrected.log.gz")
    with pytest.raises(DataError) as caught:
        data_open.open_sequence(f"aces-corrected?{key}=x[:2]")
    assert "\n" not in str(caught.value) and "got multiple values" not in str(caught.value)


@settings(max_examples=40, deadline=None)
@given(value=st.one_of(st.sampled_from(["true", "false", "True", "FALSE", "1", "0", "yes", "maybe", ""]), st.text()))
def test_parallel_bz2_is_true_false_or_one_line(value: str) -> None:
    """`?parallel_bz2=false` was the text 'false', which is true: the switch did nothing; 'maybe' passed."""
    from albot1.data.loaders.carmen.options import parse_options as carmen_options
    from albot1.data.tokens import parse_scalar

    given_value = parse_scalar(value)  # what a query's value becomes
    try:
        parsed = carmen_options(Path("log.clf"), {"parallel_bz2": given_value}).carmen.parallel_bz2
    except DataError as exc:
        assert str(exc) == f"log.clf: parallel_bz2={given_value!r}; expected true or false"
        assert not (isinstance(given_value, str) and given_value.lower() in ("true", "false"))
    else:
        assert parsed is (value.lower() == "true")


def test_a_bag_option_error_names_the_bag(tmp_path: Path) -> None:
    bag = tmp_path / "w.mcap"
    convert(f"{WORLD}[:3]", bag, "ros2-mcap")
    with pytest.raises(DataError) as caught:
        data_open.open_sequence(f"{bag}?outside_odometry=keep")
    assert str(caught.value).startswith(f"{bag}") and "outside_odometry='keep'; expected one of error, drop" in str(
        caught.value
    )
