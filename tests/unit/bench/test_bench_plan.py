"""Planning a suite: unknown datasets are errors unless optional; deterministic degradations run once."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from albot1.bench.errors import SuiteError
from albot1.bench.grid import GridPlan
from albot1.bench.plan import plan_suite
from albot1.bench.suite import load_suite
from albot1.methods.registry import MethodRegistry, MethodSpec, method_registry
from albot1.settings import Settings

WORLD = "synthetic-office-startstop"


def _plan(
    tmp_path: Path, datasets: str, grid: str = "", registry: MethodRegistry | None = None
) -> tuple[Path, GridPlan]:
    path = tmp_path / "tiny.toml"
    path.write_text(f'{grid}\n[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "{WORLD}"\n{datasets}')
    return path, plan_suite(load_suite(path), Settings(data_dir=None, cache_dir=tmp_path / "cache"), registry)


def test_a_literal_dataset_that_names_nothing_is_an_error_naming_suite_and_entry(tmp_path: Path) -> None:
    with pytest.raises(SuiteError) as caught:
        _plan(tmp_path, '[[datasets]]\nname = "no-such-log"\n')
    message = str(caught.value)
    assert message.startswith(f"{tmp_path / 'tiny.toml'}: dataset entry 'no-such-log': ")
    assert "neither a dataset name nor an existing file" in message and "optional = true" in message


def test_an_optional_unknown_dataset_is_skipped_with_its_reason(tmp_path: Path) -> None:
    _, plan = _plan(tmp_path, '[[datasets]]\nname = "no-such-log"\noptional = true\n')
    assert [s.name for s in plan.skipped_datasets] == ["no-such-log"]
    assert "neither a dataset name nor an existing file" in plan.skipped_datasets[0].reason
    assert {c.dataset for c in plan.cells} == {WORLD}


def test_a_registered_dataset_not_downloaded_is_skipped_not_an_error(tmp_path: Path) -> None:
    _, plan = _plan(tmp_path, '[[datasets]]\nname = "aces"\n')
    assert [s.name for s in plan.skipped_datasets] == ["aces"]


@pytest.mark.parametrize(
    "entry",
    [
        'name = "intel[:50]"',
        'name = "intel[:50:2]"',
        'name = "intel[::3]"',
        'name = "intel[:100][:50]"',
        'name = "intel-corrected?odometry=laser-pose[::3]"',
        'name = "intel"\nlimit = 50',
    ],
)
def test_a_sliced_dataset_not_downloaded_is_skipped_like_the_whole_one(tmp_path: Path, entry: str) -> None:
    """A slice names part of a registered log: absent, it is skipped with the fetch command, not a suite error."""
    _, plan = _plan(tmp_path, f"[[datasets]]\n{entry}\n")
    [skipped] = plan.skipped_datasets
    base = "intel-corrected" if "corrected" in entry else "intel"
    assert skipped.name == entry.split('"')[1] and skipped.hint == f"albot1 datasets fetch {base}"
    assert skipped.reason.startswith(f"not downloaded: dataset '{base}': ")
    assert {c.dataset for c in plan.cells} == {WORLD}


def test_deterministic_degradations_run_once_and_random_ones_once_per_seed(tmp_path: Path) -> None:
    grid = (
        '[grid]\ndegradations = ["thesis", "bias:0.01:0.1", "gauss:0.1:1"]\n'
        "seeds = [3, 4, 5]\nundegraded_seeds = [7, 8]\n"
    )
    _, plan = _plan(tmp_path, "sweep = true\n", grid)
    runs = sorted((c.degradation, c.seed) for c in plan.cells)
    assert runs == sorted(
        [("none", 7), ("thesis", 3), ("bias:0.01:0.1", 3), ("gauss:0.1:1", 3), ("gauss:0.1:1", 4), ("gauss:0.1:1", 5)]
    )


def test_a_stochastic_method_keeps_every_seed_under_a_deterministic_degradation(tmp_path: Path) -> None:
    """A particle filter varies with its seed even on clean odometry: its seeds are not collapsed."""
    registry = method_registry()
    stochastic = registry.with_methods(replace(registry.get("odometry"), stochastic=True))
    grid = '[grid]\ndegradations = ["thesis"]\nseeds = [3, 4]\nundegraded_seeds = [7, 8]\n'
    _, plan = _plan(tmp_path, "sweep = true\n", grid, stochastic)
    runs = sorted((c.degradation, c.seed) for c in plan.cells)
    assert runs == sorted([("none", 7), ("none", 8), ("thesis", 3), ("thesis", 4)])


def test_a_glob_that_matches_no_dataset_is_an_error_naming_the_entry(tmp_path: Path) -> None:
    with pytest.raises(SuiteError) as caught:
        _plan(tmp_path, '[[datasets]]\nname = "no-such-*"\n')
    message = str(caught.value)
    assert message.startswith(f"{tmp_path / 'tiny.toml'}: dataset entry 1 ('no-such-*') matches no dataset")
    assert WORLD in message and "optional = true" in message


def test_an_optional_glob_that_matches_nothing_is_not_an_error(tmp_path: Path) -> None:
    _, plan = _plan(tmp_path, '[[datasets]]\nname = "no-such-*"\noptional = true\n')
    assert {c.dataset for c in plan.cells} == {WORLD} and not plan.skipped_datasets


def test_a_sliced_reference_is_a_dataset_of_its_own(tmp_path: Path) -> None:
    _, plan = _plan(tmp_path, f'[[datasets]]\nname = "{WORLD}[:5]"\n[[datasets]]\nname = "{WORLD}[:6]"\n')
    labels = sorted(c.dataset_label for c in plan.cells)
    assert labels == sorted([WORLD, f"{WORLD}[:5]", f"{WORLD}[:6]"])
    assert len({c.key for c in plan.cells}) == 3


def test_spellings_of_one_slice_plan_one_run_key(tmp_path: Path) -> None:
    """`[:5]`, `[:5:1]`, `[0:5]` and `limit = 5` are the same scans: one key, one run folder, computed once."""
    _, plan = _plan(
        tmp_path,
        f'[[datasets]]\nname = "{WORLD}[:5]"\n[[datasets]]\nname = "{WORLD}[:5:1]"\n'
        f'[[datasets]]\nname = "{WORLD}[0:5]"\n[[datasets]]\nname = "{WORLD}[:10][:5]"\n',
    )
    sliced = [c for c in plan.cells if c.dataset != WORLD]
    assert len(sliced) == 4 and {c.dataset_label for c in sliced} == {f"{WORLD}[:5]"}
    assert len({c.key for c in sliced}) == 1
    [whole] = [c for c in plan.cells if c.dataset == WORLD]
    assert whole.key != sliced[0].key
    path = tmp_path / "limited.toml"
    path.write_text(f'[[methods]]\nname = "odometry"\n[[datasets]]\nname = "{WORLD}"\nlimit = 5\nstride = 1\n')
    by_limit = plan_suite(load_suite(path), Settings(data_dir=None, cache_dir=tmp_path / "cache"))
    assert [c.key for c in by_limit.cells] == [sliced[0].key]


def test_a_bad_slice_is_an_error_of_the_suite(tmp_path: Path) -> None:
    with pytest.raises(SuiteError, match=rf"tiny\.toml: dataset '{WORLD}\[:0\]': .*slice STOP is 0"):
        _plan(tmp_path, f'[[datasets]]\nname = "{WORLD}[:0]"\n')


def _methods_plan(tmp_path: Path, methods: str, registry: MethodRegistry | None = None) -> GridPlan:
    path = tmp_path / "two.toml"
    path.write_text(f'{methods}\n[[datasets]]\nname = "{WORLD}"\n')
    return plan_suite(load_suite(path), Settings(data_dir=None, cache_dir=tmp_path / "cache"), registry)


def test_cells_that_differ_only_in_their_limits_are_an_error_not_one_folder(tmp_path: Path) -> None:
    methods = (
        '[[methods]]\nname = "odometry"\nlabel = "fast"\ntime_s = 1\n'
        '[[methods]]\nname = "odometry"\nlabel = "slow"\ntime_s = 100\n'
    )
    with pytest.raises(SuiteError) as caught:
        _methods_plan(tmp_path, methods)
    message = str(caught.value)
    assert "fast on synthetic-office-startstop [none, seed 0] (time_s 1, memory_mb 4096)" in message
    assert "slow on synthetic-office-startstop [none, seed 0] (time_s 100, memory_mb 4096)" in message
    assert "same run" in message and "different limits" in message


def test_two_labels_for_the_same_run_with_the_same_limits_share_one_folder(tmp_path: Path) -> None:
    plan = _methods_plan(tmp_path, '[[methods]]\nname = "odometry"\n[[methods]]\nname = "odometry"\nlabel = "dr"\n')
    assert [c.method_label for c in plan.cells] == ["odometry", "dr"]
    assert len({c.key for c in plan.cells}) == 1


@pytest.mark.parametrize(
    "method", ["odometry", "albot1", "albot1-places", "kiss-icp", "gtsam-graph", "mrpt-icp", "mrpt-rbpf"]
)
def test_an_unknown_preset_is_an_error_of_the_suite_naming_file_entry_and_preset(tmp_path: Path, method: str) -> None:
    """Every cell of the entry would fail the same way: planning (and so `--dry-run`) refuses it with one line."""
    if not method_registry().get(method).available():
        pytest.skip(f"{method} is not installed here")
    with pytest.raises(SuiteError) as caught:
        _methods_plan(tmp_path, f'[[methods]]\nname = "odometry"\n[[methods]]\nname = "{method}"\npreset = "nosuch"\n')
    assert str(caught.value).startswith(
        f"{tmp_path / 'two.toml'}: invalid suite: methods.1 ('{method}:nosuch'): method '{method}' has no preset "
        "'nosuch'; expected one of: default"
    )
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize(
    "method", ["odometry", "albot1", "albot1-places", "kiss-icp", "gtsam-graph", "mrpt-icp", "mrpt-rbpf"]
)
def test_an_unknown_override_key_is_an_error_of_the_suite_naming_file_entry_and_key(
    tmp_path: Path, method: str
) -> None:
    if not method_registry().get(method).available():
        pytest.skip(f"{method} is not installed here")
    with pytest.raises(SuiteError) as caught:
        _methods_plan(tmp_path, f'[[methods]]\nname = "{method}"\nlabel = "mine"\nset = {{ nosuch_field = 1 }}\n')
    assert str(caught.value) == (
        f"{tmp_path / 'two.toml'}: invalid suite: methods.0 ('mine'): invalid config for method '{method}' "
        "(preset 'default'): nosuch_field: Extra inputs are not permitted (from set)"
    )


def test_an_override_value_the_method_rejects_is_an_error_of_the_suite(tmp_path: Path) -> None:
    with pytest.raises(SuiteError) as caught:
        _methods_plan(tmp_path, '[[methods]]\nname = "odometry"\nset = { map_voxel_m = -1 }\n')
    assert str(caught.value).startswith(
        f"{tmp_path / 'two.toml'}: invalid suite: methods.0 ('odometry'): invalid config for method 'odometry' "
        "(preset 'default'): map_voxel_m: Input should be greater than 0, found -1 (from set)"
    )


def test_a_method_whose_class_does_not_load_is_a_failed_cell_not_a_suite_error(tmp_path: Path) -> None:
    """A broken method is the method's fault: its cells are planned and recorded as failed with the reason."""
    broken = method_registry().with_methods(MethodSpec("broken", "no_such_module_here:Mapper"))
    plan = _methods_plan(tmp_path, '[[methods]]\nname = "broken"\npreset = "nosuch"\n', broken)
    assert [c.method for c in plan.cells] == ["broken"]
    reason = plan.config_failures[plan.cells[0].key]
    assert reason == (
        "cannot load method 'broken': no_such_module_here:Mapper: the module no_such_module_here cannot be "
        "imported: No module named 'no_such_module_here'"
    )


@pytest.mark.parametrize(
    ("setting", "problem"),
    [
        ("map_voxel_m = true", "map_voxel_m: found the boolean true, expected a number"),
        ('map_every = "2"', "map_every: found the string '2', expected an integer"),
        ("map_every = 2.0", "map_every: found the float 2.0, expected an integer"),
        ('map_voxel_m = "0.1"', "map_voxel_m: found the string '0.1', expected a number"),
    ],
)
def test_a_suite_set_value_of_another_type_is_an_error_not_converted(
    tmp_path: Path, setting: str, problem: str
) -> None:
    """TOML values are typed: ``true`` is not 1.0 and ``"2"`` or ``2.0`` is not 2 (``--dry-run`` must say so)."""
    with pytest.raises(SuiteError) as caught:
        _methods_plan(tmp_path, f'[[methods]]\nname = "odometry"\nset = {{ {setting} }}\n')
    assert str(caught.value) == (
        f"{tmp_path / 'two.toml'}: invalid suite: methods.0 ('odometry'): invalid config for method 'odometry' "
        f"(preset 'default'): {problem} (from set)"
    )


def test_a_suite_set_int_for_a_float_field_is_fine(tmp_path: Path) -> None:
    plan = _methods_plan(tmp_path, '[[methods]]\nname = "odometry"\nset = { map_voxel_m = 1, map_every = 3 }\n')
    config = plan.cells[0].config
    assert (config["map_voxel_m"], config["map_every"]) == (1.0, 3)


@pytest.mark.parametrize(
    ("grid", "entry", "why"),
    [
        ("[grid]\nundegraded_seeds = []\ndegradations = []", "", "its degradations list is empty"),
        ("[grid]\nundegraded_seeds = []", "sweep = false\n", "no degradation is swept on it (sweep = false)"),
        (
            "[grid]\nundegraded_seeds = []",
            'degradations = ["none"]\n',
            "its degradations list names only `none` (the undegraded run, which has no seed here)",
        ),
    ],
)
def test_a_dataset_that_plans_no_run_is_listed_as_skipped_with_why(
    tmp_path: Path, grid: str, entry: str, why: str
) -> None:
    """out49: it vanished from the grid without a word; the bench then blamed skipped datasets it never named."""
    path = tmp_path / "tiny.toml"
    path.write_text(
        f'{grid}\n[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "{WORLD}"\n{entry}'
        '\n[[datasets]]\nname = "synthetic-corridor"\nundegraded_seeds = [0]\n'
    )
    plan = plan_suite(load_suite(path), Settings(data_dir=None, cache_dir=tmp_path / "cache"))
    assert [(s.name, s.reason) for s in plan.skipped_datasets] == [
        (WORLD, f"no cell planned: undegraded_seeds is empty and {why}")
    ]
    assert {(c.dataset, c.degradation) for c in plan.cells} == {("synthetic-corridor", "none")}
