"""Property tests of suite files: whatever a TOML file holds, only the documented SuiteError comes out.

Suites are generated as Python tables from the documented keys (plus
unknown ones and values of every TOML type) and rendered to TOML text, so
that the whole path -- reading, TOML parsing, validation, planning -- is
exercised; raw bytes and text check the reader alone.
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from albot1.bench.errors import SuiteError
from albot1.bench.plan import plan_suite
from albot1.bench.suite import MAX_MEMORY_MB, MAX_TIME_S, SUITE_NAME, Suite, load_suite
from albot1.data.degrade import MAX_SEED
from albot1.settings import Settings

# -- a TOML writer for generated tables (keys always quoted; TOML's escapes are JSON's) ---------------------------


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(type(value))


def to_toml(table: dict[str, Any]) -> str:
    lines = [f"{json.dumps(k)} = {_value(v)}" for k, v in table.items() if not _is_table(v)]
    for key, value in table.items():
        if isinstance(value, dict):
            lines += [f"[{json.dumps(key)}]", *(f"{json.dumps(k)} = {_value(v)}" for k, v in value.items())]
        elif _is_table(value):
            for item in value:
                lines += [f"[[{json.dumps(key)}]]", *(f"{json.dumps(k)} = {_value(v)}" for k, v in item.items())]
    return "\n".join(lines) + "\n"


def _is_table(value: Any) -> bool:
    return isinstance(value, dict) or (
        isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)
    )


# -- strategies ---------------------------------------------------------------------------------------------------

SCALARS = st.one_of(
    st.booleans(),
    st.integers(-(2**63), 2**63 - 1),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
)
ANY = st.one_of(SCALARS, st.lists(SCALARS, max_size=3))
NUMBERS = st.one_of(
    st.integers(-5, 10),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([1e12, MAX_TIME_S, MAX_MEMORY_MB, 0.001]),
)
SEEDS = st.lists(st.one_of(st.integers(-3, 5), st.sampled_from([MAX_SEED, MAX_SEED + 1])), max_size=3)
SPECS = st.lists(st.sampled_from(["none", "thesis", "gauss:0.1:1", "bias:0.1:1", "gauss:1", "noise", ""]), max_size=3)
#: Names planning can answer quickly: a small world, registered datasets (absent here), unknown names, globs, slices.
DATASET_NAMES = st.sampled_from(
    [
        "synthetic-office-startstop",
        "synthetic-office-startstop[:5]",
        "synthetic-office-startstop[:0]",
        "synthetic-office-startstop[::2]",
        "synthetic-office-startstop?views=1:10",
        "synthetic-office-startstop?views=x",
        "aces",
        "aces[:100]",
        "intel*",
        "no-such-log",
        "no-such-*",
        "*",
        "[",
        "synthetic-office-startstop[:5",
        "",
    ]
)
METHOD_NAMES = st.sampled_from(["odometry", "no-such-method", ""])


def _entry(base: dict[str, st.SearchStrategy[Any]]) -> st.SearchStrategy[dict[str, Any]]:
    return st.fixed_dictionaries({}, optional={**base, "unknown_key": ANY})


DATASET_ENTRY = _entry(
    {
        "name": st.one_of(DATASET_NAMES, st.text(max_size=8)),
        "skip": st.booleans(),
        "optional": st.booleans(),
        "limit": NUMBERS,
        "stride": NUMBERS,
        "sweep": st.one_of(st.booleans(), st.sampled_from(["auto", "yes"])),
        "degradations": SPECS,
        "seeds": SEEDS,
        "undegraded_seeds": SEEDS,
        "time_s": NUMBERS,
        "memory_mb": NUMBERS,
    }
)
METHOD_ENTRY = _entry(
    {
        "name": METHOD_NAMES,
        "preset": st.sampled_from(["default", "no-such-preset"]),
        "set": st.dictionaries(st.sampled_from(["map_voxel_m", "nonsense"]), SCALARS, max_size=2),
        "label": st.text(max_size=6),
        "target": st.sampled_from(["no.such.module:Class", "not a target", "albot1.methods.baselines.odometry:X"]),
        "time_s": NUMBERS,
        "memory_mb": NUMBERS,
    }
)
SUITE = st.fixed_dictionaries(
    {},
    optional={
        "name": st.one_of(st.sampled_from(["ok", "..", ".x", "a/b", "fine-1.0"]), st.text(max_size=8)),
        "description": st.text(max_size=10),
        "registered_methods": st.booleans(),
        "limits": st.fixed_dictionaries({}, optional={"time_s": NUMBERS, "memory_mb": NUMBERS, "extra": ANY}),
        "grid": st.fixed_dictionaries(
            {}, optional={"degradations": SPECS, "seeds": SEEDS, "undegraded_seeds": SEEDS, "extra": ANY}
        ),
        "methods": st.lists(METHOD_ENTRY, max_size=2),
        "datasets": st.lists(DATASET_ENTRY, max_size=3),
        "surprise": ANY,
    },
)


# Mostly-valid suites, so that validation passes often enough for planning to be exercised too.
GOOD_NUMBERS = st.one_of(st.integers(1, 100), st.floats(0.5, 1000.0))
TAME_DATASET = st.fixed_dictionaries(
    {"name": DATASET_NAMES},
    optional={
        "skip": st.booleans(),
        "optional": st.booleans(),
        "limit": st.integers(1, 50),
        "stride": st.integers(1, 3),
        "sweep": st.sampled_from([True, False, "auto"]),
        "degradations": st.lists(st.sampled_from(["none", "thesis", "gauss:0.1:1"]), max_size=2),
        "seeds": st.lists(st.integers(0, 3), max_size=2),
        "undegraded_seeds": st.lists(st.integers(0, 3), max_size=2),
        "time_s": GOOD_NUMBERS,
        "memory_mb": GOOD_NUMBERS,
    },
)
TAME_METHOD = st.fixed_dictionaries(
    {"name": st.sampled_from(["odometry", "odometry", "no-such-method"])},
    optional={
        "label": st.sampled_from(["a", "b", "odometry"]),
        "set": st.sampled_from([{}, {"map_voxel_m": -1}, {"nonsense": 1}]),
        "time_s": GOOD_NUMBERS,
        "memory_mb": GOOD_NUMBERS,
    },
)
TAME_SUITE = st.fixed_dictionaries(
    {
        "methods": st.lists(TAME_METHOD, min_size=1, max_size=2),
        "datasets": st.lists(TAME_DATASET, min_size=1, max_size=3),
    },
    optional={
        "name": st.sampled_from(["ok", "fine-1.0", ".."]),
        "limits": st.fixed_dictionaries({}, optional={"time_s": NUMBERS, "memory_mb": GOOD_NUMBERS}),
        "grid": st.fixed_dictionaries(
            {}, optional={"degradations": SPECS, "seeds": SEEDS, "undegraded_seeds": st.lists(st.integers(0, 2))}
        ),
    },
)
ANY_SUITE = st.one_of(TAME_SUITE, SUITE)


def _load(text: str | bytes) -> Suite | None:
    """load_suite on a file holding ``text``: the suite, or None after the documented SuiteError."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "fuzz.toml"
        if isinstance(text, bytes):
            path.write_bytes(text)
        else:
            path.write_text(text, encoding="utf-8", errors="surrogatepass")
        try:
            return load_suite(path)
        except SuiteError as exc:
            message = str(exc)
            assert message.startswith(str(path)) or message.startswith("fuzz.toml") or str(path) in message
            assert "\n" not in message.strip() or "TOML" in message  # one line, except tomllib's own excerpt
            return None


def _check_model(suite: Suite) -> None:
    """A suite that validated holds the documented bounds and answers every question without raising."""
    assert SUITE_NAME.fullmatch(suite.name)
    assert 0 < suite.limits.time_s <= MAX_TIME_S and 0 < suite.limits.memory_mb <= MAX_MEMORY_MB
    assert all(0 <= s <= MAX_SEED for s in (*suite.grid.seeds, *suite.grid.undegraded_seeds))
    for entry in suite.datasets:
        assert entry.is_pattern in (True, False)
        options = suite.options_for(entry.name)
        if options is not None:  # the label spells the slice one way (intel[:5:1] -> intel[:5]); the name stays
            assert options.label.startswith(options.name.partition("[")[0])
    suite.literal_datasets()
    [m.display for m in suite.methods]


@settings(max_examples=200, deadline=None)
@given(st.one_of(st.text(max_size=60), st.binary(max_size=60)))
def test_any_file_content_loads_or_raises_suite_error(text: str | bytes) -> None:
    suite = _load(text)
    if suite is not None:
        _check_model(suite)


@settings(max_examples=300, deadline=None)
@given(ANY_SUITE)
def test_generated_suites_validate_or_raise_suite_error(table: dict[str, Any]) -> None:
    suite = _load(to_toml(table))
    if suite is not None:
        _check_model(suite)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(TAME_SUITE)
def test_planning_a_valid_suite_raises_only_suite_errors(table: dict[str, Any]) -> None:
    suite = _load(to_toml(table))
    if suite is None:
        return
    with tempfile.TemporaryDirectory() as folder:
        try:
            plan = plan_suite(suite, Settings(data_dir=None, cache_dir=Path(folder)))
        except SuiteError as exc:
            assert "\n" not in str(exc)
            return
    limits: dict[str, tuple[float, float]] = {}
    for cell in plan.cells:  # one run folder, one set of limits
        assert limits.setdefault(cell.key, (cell.time_s, cell.memory_mb)) == (cell.time_s, cell.memory_mb)
        assert cell.seed >= 0 and 0 < cell.time_s <= MAX_TIME_S
