"""Suite files: parsing, validation errors that name file and key, option merging, shipped suites."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.bench.errors import BenchError, SuiteError
from albot1.bench.executors import parse_executor
from albot1.bench.suite import find_suite, load_suite, parse_suite
from albot1.resources import shipped_dir

MINIMAL = {"methods": [{"name": "odometry"}], "datasets": [{"name": "*"}]}


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "s.toml"
    path.write_text(text)
    return path


def test_minimal_suite_defaults() -> None:
    suite = parse_suite(MINIMAL, name="s", source="s.toml")
    assert suite.limits.time_s == 900 and suite.limits.memory_mb == 4096
    assert suite.grid.degradations == () and suite.grid.undegraded_seeds == (0,)
    assert suite.methods[0].display == "odometry"


def test_later_entries_override_earlier_ones_field_by_field() -> None:
    suite = parse_suite(
        {
            "methods": [{"name": "odometry"}],
            "datasets": [
                {"name": "*", "stride": 2, "time_s": 30},
                {"name": "intel*", "limit": 100},
                {"name": "intel-corrected", "stride": 1},
                {"name": "aces", "skip": True},
            ],
        },
        name="s",
        source="s.toml",
    )
    intel = suite.options_for("intel-corrected")
    assert intel is not None
    assert (intel.limit, intel.stride, intel.time_s) == (100, 1, 30)
    assert intel.label == "intel-corrected[:100]"  # a stride of 1 is no stride: one spelling, one run key
    other = suite.options_for("fr079")
    assert other is not None and other.label == "fr079[::2]"
    assert suite.options_for("aces") is None
    assert suite.literal_datasets() == ["intel-corrected"]


def test_method_labels_include_non_default_presets_and_must_be_unique() -> None:
    suite = parse_suite(
        {
            "methods": [{"name": "albot1", "preset": "thesis"}, {"name": "albot1", "preset": "exact"}],
            "datasets": [{"name": "*"}],
        },
        name="s",
        source="s.toml",
    )
    assert [m.display for m in suite.methods] == ["albot1:thesis", "albot1:exact"]
    with pytest.raises(SuiteError, match="both labelled 'odometry'"):
        parse_suite(
            {"methods": [{"name": "odometry"}, {"name": "odometry"}], "datasets": [{"name": "*"}]},
            name="s",
            source="s.toml",
        )


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('methods = [{name = "odometry"}]\ndatasets = [{name = "*", strde = 2}]\n', r"s\.toml:2: .*datasets\.0\.strde"),
        ('methods = [{name = "odometry"}]\ndatasets = [{name = "*", limit = 0}]\n', r"datasets\.0\.limit"),
        ('methods = []\ndatasets = [{name = "*"}]\n', r"methods"),
        (
            'methods = [{name = "odometry"}]\ndatasets = [{name = "*"}]\n[grid]\ndegradations = ["gauss:1"]\n',
            r"grid\.degradations.*gauss:SIGMA_XY_M",
        ),
        ('methods = [{name = "odometry"}]\nx = = 1\n', r"s\.toml: not valid TOML.*line 2"),
    ],
)
def test_invalid_suites_name_file_and_key(tmp_path: Path, text: str, expected: str) -> None:
    with pytest.raises(SuiteError, match=expected):
        load_suite(write(tmp_path, text))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        # an empty list that would drop cells without a word (adversarial test, session 13): refused, one line
        ('methods = [{name = "odometry"}]\ndatasets = [{name = "*"}]\n[grid]\nseeds = []\n', "grid.seeds: "),
        ('methods = [{name = "odometry"}]\ndatasets = [{name = "*", seeds = []}]\n', "datasets.0.seeds: "),
        ('methods = [{name = "odometry", datasets = []}]\ndatasets = [{name = "*"}]\n', "methods.0.datasets: "),
        ('methods = [{name = "odometry"}]\ndatasets = [{name = "*", methods = []}]\n', "datasets.0.methods: "),
        # a seed or perturbation listed twice would plan its cells twice and weight them twice in a mean
        ('methods = [{name = "odometry"}]\ndatasets = [{name = "*"}]\n[grid]\nseeds = [0, 0, 1]\n', "grid.seeds: "),
        ('methods = [{name = "odometry"}]\ndatasets = [{name = "*", undegraded_seeds = [2, 2]}]\n', "datasets.0.undeg"),
        (
            'methods = [{name = "odometry"}]\ndatasets = [{name = "*"}]\n[grid]\n'
            'degradations = ["gauss:0.05:2", "gauss:0.050:2.0"]\n',
            "grid.degradations: ",
        ),
        # a bad key in the only entry: that key alone, not also "methods: at least 1 item"
        ('methods = [{name = "odometry", presett = "x"}]\ndatasets = [{name = "*"}]\n', "methods.0.presett: "),
    ],
)
def test_empty_lists_and_a_bad_entry_are_one_problem_each(tmp_path: Path, text: str, expected: str) -> None:
    with pytest.raises(SuiteError) as caught:
        load_suite(write(tmp_path, text))
    problems = str(caught.value).split(": invalid suite: ", 1)[1].split("; ")
    assert len(problems) == 1 and problems[0].startswith(expected), str(caught.value)


def test_a_suite_of_degraded_runs_only_may_leave_the_undegraded_seeds_empty(tmp_path: Path) -> None:
    text = 'methods = [{name = "odometry"}]\ndatasets = [{name = "*"}]\n[grid]\nundegraded_seeds = []\n'
    assert load_suite(write(tmp_path, text)).grid.undegraded_seeds == ()


def test_suite_name_defaults_to_file_stem(tmp_path: Path) -> None:
    path = write(tmp_path, 'methods = [{name = "odometry"}]\ndatasets = [{name = "*"}]\n')
    assert load_suite(path).name == "s"


def test_find_suite_by_name_and_path(tmp_path: Path) -> None:
    assert find_suite("quick") == shipped_dir("benchmarks") / "quick.toml"
    path = write(tmp_path, "")
    assert find_suite(str(path)) == path
    with pytest.raises(SuiteError, match="no suite named 'nope'.*quick"):
        find_suite("nope")
    with pytest.raises(SuiteError, match="suite file not found"):
        find_suite(str(tmp_path / "missing.toml"))


@pytest.mark.parametrize("name", ["default", "quick", "full"])
def test_shipped_suites_are_valid(name: str) -> None:
    suite = load_suite(find_suite(name))
    assert suite.name == name
    assert {"odometry", "albot1"} <= {m.name for m in suite.methods}


def test_parse_executor() -> None:
    assert parse_executor("local") == ("local", None)
    assert parse_executor("dask") == ("dask", None)
    assert parse_executor("dask://10.0.0.1:8786") == ("dask", "tcp://10.0.0.1:8786")
    with pytest.raises(BenchError, match="expected local | dask"):
        parse_executor("ray")


def test_reference_with_loader_options_is_a_literal_entry() -> None:
    suite = parse_suite(
        {
            "methods": [{"name": "odometry"}],
            "datasets": [
                {"name": "*", "sweep": False},
                {"name": "intel-corrected?odometry=laser-pose", "sweep": True},
            ],
        },
        name="s",
        source="s.toml",
    )
    assert suite.literal_datasets() == ["intel-corrected?odometry=laser-pose"]
    opts = suite.options_for("intel-corrected?odometry=laser-pose")
    assert opts is not None and opts.sweep is True
    plain = suite.options_for("intel-corrected")
    assert plain is not None and plain.sweep is False


@pytest.mark.parametrize("name", ["..", ".", ".hidden", "a/b", "../escape", "a b", "x" * 101, ""])
def test_a_suite_name_must_be_a_plain_folder_name(name: str) -> None:
    with pytest.raises(SuiteError, match=r"s\.toml: invalid suite: name: .*plain folder name"):
        parse_suite(MINIMAL, name=name, source="s.toml")


@pytest.mark.parametrize("name", ["quick", "my-suite_2.v1", "9"])
def test_plain_suite_names_are_accepted(name: str) -> None:
    assert parse_suite(MINIMAL, name=name, source="s.toml").name == name


@pytest.mark.parametrize(
    ("table", "expected"),
    [
        ("[limits]\ntime_s = 1e12\n", r"limits\.time_s: Input should be less than or equal to 604800"),
        ("[limits]\ntime_s = inf\n", r"limits\.time_s"),
        ("[limits]\ntime_s = nan\n", r"limits\.time_s"),
        ("[limits]\ntime_s = 0\n", r"limits\.time_s: Input should be greater than 0"),
        ("[limits]\nmemory_mb = 1e9\n", r"limits\.memory_mb: Input should be less than or equal to 1048576"),
        ("[grid]\nseeds = [-1]\n", r"grid\.seeds\.0: Input should be greater than or equal to 0"),
        ("[grid]\nundegraded_seeds = [0, -3]\n", r"grid\.undegraded_seeds\.1"),
    ],
)
def test_limits_and_seeds_are_bounded(tmp_path: Path, table: str, expected: str) -> None:
    path = write(tmp_path, table + '\n[[methods]]\nname = "odometry"\n[[datasets]]\nname = "*"\n')
    with pytest.raises(SuiteError, match=expected):
        load_suite(path)


def test_entry_limits_and_seeds_are_bounded_too() -> None:
    for entry, key in (
        ({"name": "*", "time_s": 1e12}, "datasets.0.time_s"),
        ({"name": "*", "seeds": [-2]}, "datasets.0.seeds.0"),
    ):
        with pytest.raises(SuiteError, match=key.replace(".", r"\.")):
            parse_suite({"methods": [{"name": "odometry"}], "datasets": [entry]}, name="s", source="s.toml")
    with pytest.raises(SuiteError, match=r"methods\.0\.memory_mb"):
        parse_suite(
            {"methods": [{"name": "odometry", "memory_mb": -1}], "datasets": [{"name": "*"}]}, name="s", source="s"
        )


@pytest.mark.parametrize(
    ("name", "pattern"),
    [
        ("intel[:100]", False),
        ("intel[:100:2]", False),
        ("intel[::2]", False),
        ("intel[:30][:20]", False),
        ("intel[0:300]", False),
        ("intel-corrected?odometry=laser-pose[:100]", False),
        ("intel*", True),
        ("intel*[:100]", True),
        ("intel-[ab]*", True),
        ("log[1].clf", True),
    ],
)
def test_a_trailing_slice_is_a_literal_reference_not_a_glob(name: str, pattern: bool) -> None:
    suite = parse_suite({"methods": [{"name": "odometry"}], "datasets": [{"name": name}]}, name="s", source="s")
    assert suite.datasets[0].is_pattern is pattern
    assert suite.literal_datasets() == ([] if pattern else [name])


def test_a_suite_file_that_is_not_utf8_text_is_one_error(tmp_path: Path) -> None:
    path = tmp_path / "binary.toml"
    path.write_bytes(b"\xff\xfe\x00name")
    with pytest.raises(SuiteError, match=r"binary\.toml: not UTF-8 text \(byte 0\)"):
        load_suite(path)


def test_a_suite_cannot_set_its_own_path() -> None:
    with pytest.raises(SuiteError, match="path: unknown key"):
        parse_suite({**MINIMAL, "path": "/elsewhere"}, name="s", source="s.toml")


@pytest.mark.parametrize(
    ("key", "value"),
    [("target", '"this:x"'), ("requires", '["this.x"]'), ("error_class", '"os:system"'), ("target", '"nocolon"')],
)
def test_a_suite_cannot_name_code_to_import(tmp_path: Path, key: str, value: str) -> None:
    """``target`` / ``requires`` / ``error_class`` are refused with one line, before anything is imported."""
    text = f'[[methods]]\nname = "odometry"\n\n[[methods]]\nname = "mine"\n{key} = {value}\n[[datasets]]\nname = "*"\n'
    with pytest.raises(SuiteError) as caught:
        load_suite(write(tmp_path, text))
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith(f"{tmp_path / 's.toml'}: invalid suite: ")
    assert f"methods.1 ('mine'): `{key}` is not read" in message and "entry point group albot1.methods" in message


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        # a value of the wrong TOML type is refused, never converted (adversarial test: `memory_mb = true` was 1 MiB)
        ("[limits]\nmemory_mb = true\n", "limits.memory_mb: Input should be a valid number, found the boolean true"),
        ('[limits]\ntime_s = "60"\n', "limits.time_s: Input should be a valid number, found the string '60'"),
        ("[grid]\nseeds = [true]\n", "grid.seeds.0: Input should be a valid integer, found the boolean true"),
        ('[grid]\nseeds = ["5"]\n', "grid.seeds.0: Input should be a valid integer, found the string '5'"),
        ("[grid]\nseeds = 5\n", "grid.seeds: Input should be a valid tuple, found the integer 5"),
        (
            "[grid]\nundegraded_seeds = [1.0]\n",
            "grid.undegraded_seeds.0: Input should be a valid integer, found the number 1.0",
        ),
        ("registered_methods = 1\n", "registered_methods: Input should be a valid boolean, found the integer 1"),
        ("description = 3\n", "description: Input should be a valid string, found the integer 3"),
    ],
)
def test_a_value_of_the_wrong_type_is_one_problem_naming_what_was_found(
    tmp_path: Path, text: str, expected: str
) -> None:
    with pytest.raises(SuiteError) as caught:
        load_suite(write(tmp_path, text + '[[methods]]\nname = "odometry"\n[[datasets]]\nname = "*"\n'))
    line = 2 if text.startswith("[") else 1  # the key's line, after its table header
    assert str(caught.value) == f"{tmp_path / 's.toml'}:{line}: invalid suite: {expected}"


@pytest.mark.parametrize(
    ("entry", "expected"),
    [
        ('{name = "*", limit = 5.0}', "datasets.0.limit: Input should be a valid integer, found the number 5.0"),
        ('{name = "*", stride = "2"}', "datasets.0.stride: Input should be a valid integer, found the string '2'"),
        ('{name = "*", sweep = 1}', 'datasets.0.sweep: Input should be true, false or "auto", found the integer 1'),
        (
            '{name = "*", sweep = "yes"}',
            "datasets.0.sweep: Input should be true, false or \"auto\", found the string 'yes'",
        ),
        (
            '{name = "*", seeds = [false]}',
            "datasets.0.seeds.0: Input should be a valid integer, found the boolean false",
        ),
        (
            '{name = "*", memory_mb = false}',
            "datasets.0.memory_mb: Input should be a valid number, found the boolean false",
        ),
        ('{name = "*", skip = "no"}', "datasets.0.skip: Input should be a valid boolean, found the string 'no'"),
        ("{name = 5}", "datasets.0.name: Input should be a valid string, found the integer 5"),
        ('{name = "*", tags = "x"}', "datasets.0.tags: Input should be a valid tuple, found the string 'x'"),
    ],
)
def test_a_dataset_entry_value_of_the_wrong_type_is_refused(tmp_path: Path, entry: str, expected: str) -> None:
    with pytest.raises(SuiteError) as caught:
        load_suite(write(tmp_path, f'methods = [{{name = "odometry"}}]\ndatasets = [{entry}]\n'))
    assert str(caught.value) == f"{tmp_path / 's.toml'}:2: invalid suite: {expected}"


@pytest.mark.parametrize(
    ("entry", "expected"),
    [
        (
            '{name = "odometry", time_s = true}',
            "methods.0.time_s: Input should be a valid number, found the boolean true",
        ),
        (
            '{name = "odometry", allow_failure = "yes"}',
            "methods.0.allow_failure: Input should be a valid boolean, found",
        ),
        ('{name = "odometry", set = [1]}', "methods.0.set: Input should be a valid dictionary, found a list of 1 item"),
        ('{name = "odometry", preset = 1}', "methods.0.preset: Input should be a valid string, found the integer 1"),
    ],
)
def test_a_method_entry_value_of_the_wrong_type_is_refused(tmp_path: Path, entry: str, expected: str) -> None:
    with pytest.raises(SuiteError) as caught:
        load_suite(write(tmp_path, f'methods = [{entry}]\ndatasets = [{{name = "*"}}]\n'))
    message = str(caught.value)
    assert message.startswith(f"{tmp_path / 's.toml'}:1: invalid suite: {expected}") and "; " not in message, message


def test_integers_stand_for_floats_and_arrays_for_lists(tmp_path: Path) -> None:
    """TOML writes `time_s = 60` for a float field and arrays where the model holds tuples: both stay accepted."""
    text = (
        '[limits]\ntime_s = 60\nmemory_mb = 512\n[grid]\nseeds = [0, 1]\ndegradations = ["thesis"]\n'
        '[[methods]]\nname = "odometry"\ntime_s = 30\ndatasets = ["a*"]\n'
        '[[datasets]]\nname = "*"\nmemory_mb = 100\nsweep = "auto"\ntags = ["t"]\nmethods = ["odometry"]\n'
    )
    suite = load_suite(write(tmp_path, text))
    assert (suite.limits.time_s, suite.limits.memory_mb) == (60.0, 512.0)
    assert isinstance(suite.limits.time_s, float) and suite.grid.seeds == (0, 1)
    assert suite.methods[0].time_s == 30.0 and suite.methods[0].datasets == ("a*",)
    assert suite.datasets[0].memory_mb == 100.0 and suite.datasets[0].tags == ("t",)


@pytest.mark.parametrize(
    ("entry", "label"),
    [
        ('name = "intel[:300]"', "intel[:300]"),
        ('name = "intel[:300:1]"', "intel[:300]"),
        ('name = "intel[0:300]"', "intel[:300]"),
        ('name = "intel[:0300]"', "intel[:300]"),
        ('name = "intel[:600][:300]"', "intel[:300]"),
        ('name = "intel"\nlimit = 300', "intel[:300]"),
        ('name = "intel"\nlimit = 300\nstride = 1', "intel[:300]"),
        ('name = "intel[:600]"\nlimit = 300', "intel[:300]"),
        ('name = "intel[::1]"', "intel"),
        ('name = "intel[::3]"\nlimit = 100', "intel[:300:3]"),
        ('name = "intel"\nlimit = 4000\nstride = 2', "intel[:4000:2]"),
        ('name = "x-corrected?odometry=laser-pose[::3]"', "x-corrected?odometry=laser-pose[::3]"),
    ],
)
def test_every_spelling_of_a_slice_is_labelled_one_way(tmp_path: Path, entry: str, label: str) -> None:
    """The label is hashed into the run key: equal slices share one key, so their cells are computed once."""
    suite = load_suite(write(tmp_path, f'[[methods]]\nname = "odometry"\n[[datasets]]\n{entry}\n'))
    options = suite.options_for(suite.datasets[0].name)
    assert options is not None and options.label == label


def test_an_invalid_suite_names_the_line_of_the_key(tmp_path: Path) -> None:
    """``file:LINE``: in a suite of many ``[[datasets]]`` entries an index alone left the user counting headers."""
    text = (
        '# a comment\n[grid]\ndegradations = [\n  "thesis",\n]\nseeds = [0]\n\n[[methods]]\nname = "odometry"\n'
        'set = { x = 1 }\n[[datasets]]\nname = "a"\n[[datasets]]\nname = "b"\ndescription = """\ncolour = 1\n"""\n'
        "colour = 3\n"
    )
    with pytest.raises(SuiteError) as caught:
        load_suite(write(tmp_path, text))
    assert str(caught.value) == (
        f"{tmp_path / 's.toml'}:15: invalid suite: datasets.1.description: Extra inputs are not permitted; "
        "datasets.1.colour: Extra inputs are not permitted"
    )
    bad_seed = text.replace("seeds = [0]", "seeds = [-1]")
    with pytest.raises(SuiteError, match=r"s\.toml:6: invalid suite: grid\.seeds\.0: "):
        load_suite(write(tmp_path, bad_seed))
