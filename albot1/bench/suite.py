"""Benchmark suites: TOML files in ``benchmarks/`` parsed into a typed, validated model.

A suite says *what could* run (dataset patterns x method entries x
degradations x seeds, with per-cell limits); :mod:`albot1.bench.plan` turns
it into the cells that *will* run on this machine (datasets present, method
dependencies installed). Keeping the two apart lets one suite file serve a
laptop without downloads and a machine with every log.

Format (every key optional except ``methods`` and ``datasets``)::

    name = "default"                 # defaults to the file stem
    description = "..."
    registered_methods = true        # also run every other registered, installed method
                                     # (not those registered with auto_include=False: mrpt-*)

    [limits]                         # per-cell defaults
    time_s = 900                     # wall-clock limit of one cell (at most 7 days)
    memory_mb = 4096                 # resident memory of one cell and the processes it starts (at most 1 TiB)

    [grid]
    degradations = ["thesis", "gauss:0.05:0.5"]   # swept on datasets with reference poses
    seeds = [0, 1, 2]                # seeds of every swept degradation
    undegraded_seeds = [0]           # seeds of the run on the dataset's own odometry

    [[methods]]
    name = "albot1"
    preset = "thesis"
    set = { some_field = 1 }         # config overrides (highest precedence)
    # label = "albot1:thesis"        # defaults to name, or name:preset
    # datasets = ["aces", "fr*"]     # only on the selected datasets these globs match; default: all
    # allow_failure = true           # its failed cells (divergence, crash, limits) are findings:
                                     # reported with their reason, not a non-zero exit of the bench

    [[methods]]                      # another system's output, scored beside the methods run
    name = "cartographer"
    trajectories = "runs/carto/{dataset}.tum"   # one file per dataset (relative to the suite file);
                                     # {dataset}: the dataset's name (a path's stem); see albot1/bench/external.py
    # trajectory_format = "tum"      # tum | kitti | carmen (default: guessed from each file)

    [[datasets]]                     # applied in order; later entries override earlier ones
    name = "*"                       # a glob (* and [...]) over dataset and world names, a name, a
                                     # dataset reference with loader options (NAME?KEY=VALUE) or a
                                     # slice (NAME[:N], NAME[:N:S]), or a path
    [[datasets]]
    name = "intel"
    limit = 4000                     # first 4000 scans ...
    stride = 2                       # ... every 2nd of them
    sweep = false                    # true | false | "auto" (= when the dataset has reference poses)
    # degradations / seeds / undegraded_seeds / time_s / memory_mb / skip = true
    # optional = true                # a name or path that does not exist, or a glob that matches
                                     # nothing, is skipped instead of being an error
    # methods = ["albot1:thesis"]    # only these method entries (by label) run on it; default: all
    # tags = ["dense-views"]         # names a report finds this entry's datasets by (the thesis page's
                                     # experiments, docs/thesis-reproduction.md); not merged, no effect on runs

A method entry names a registered method: a built-in one (``albot1 methods``)
or one an installed distribution declares under the entry point group
``albot1.methods`` (:mod:`albot1.methods.plugins`). A suite file cannot name
a module to import: ``target``, ``error_class`` and ``requires`` are refused.

A literal dataset entry (not a glob) that names no synthetic world, no
registered dataset and no existing file, and a glob that matches no dataset,
are errors of the suite unless the entry says ``optional = true``; a
registered dataset that is not downloaded is skipped with the command that
fetches it. A trailing slice (``NAME[:N]``) is not a glob: the entry names
that prefix. The deterministic degradations (``none``, ``thesis``,
``bias:...``) run with the first seed of their list only: every other seed
would repeat the same run.

Bounds, so that a typo fails here rather than deep in the runner: the suite
name is a plain folder name (it names ``RESULTS/<name>``), seeds are 0 ..
2**63 - 1, ``time_s`` is at most 7 days and ``memory_mb`` at most 1 TiB.
"""

from __future__ import annotations

import fnmatch
import re
import tomllib
from pathlib import Path
from typing import Annotated, Any, Literal, TypeVar

from pydantic import BaseModel, ConfigDict, Field, Strict, ValidationError, field_validator, model_validator
from pydantic_core import PydanticCustomError

from albot1.bench.errors import SuiteError
from albot1.config.toml_lines import key_lines, line_of
from albot1.config.validation import describe_errors
from albot1.data.degrade import MAX_SEED, DegradationSpecError, parse_spec
from albot1.data.errors import SliceError
from albot1.data.open import canonical_reference, slice_reference
from albot1.resources import list_resources, resource_dirs

# "?" is not a glob character here: in a dataset reference it introduces loader options
# (``intel-corrected?odometry=laser-pose``, see albot1.data.open), so such an entry is a literal.
GLOB_CHARS = frozenset("*[")
#: A trailing ``[:STOP]`` / ``[:STOP:STEP]`` / ``[::STEP]`` (or ``[0:STOP]``) is a slice of a dataset reference,
#: not a glob class.
_TRAILING_SLICE = re.compile(r"\[[0-9]*:[^\[\]]*\]$")
#: Upper bounds of the per-cell limits: beyond them a value is a typo, and a timer or a byte count would overflow.
MAX_TIME_S = 7 * 24 * 3600.0
MAX_MEMORY_MB = 1024.0 * 1024.0
TimeS = Annotated[float, Field(gt=0, le=MAX_TIME_S, description="wall-clock seconds before the cell is killed")]
MemoryMb = Annotated[
    float,
    Field(gt=0, le=MAX_MEMORY_MB, description="resident memory of the cell and the processes it starts, MiB"),
]
Seed = Annotated[int, Field(ge=0, le=MAX_SEED)]
# A TOML array is a Python list: ``Strict(False)`` lets a list stand for the tuple, its items stay strict.
#: Names, globs or degradation specs (a TOML array of strings).
Names = Annotated[tuple[str, ...], Strict(False)]
#: Seeds (a TOML array of integers; ``true`` is not seed 1).
Seeds = Annotated[tuple[Seed, ...], Strict(False)]
#: A suite's name is the folder of its results (``RESULTS/<name>``): a plain name that cannot climb out of it.
SUITE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,99}")


#: Keys a method entry once read to import a module of the suite's choosing (refused with a pointer to plugins).
REMOVED_METHOD_KEYS = ("target", "error_class", "requires")


class _Strict(BaseModel):
    """No unknown key, and no value of the wrong TOML type turned into another (``memory_mb = true`` is not 1 MiB).

    Strict validation refuses a boolean for a number, a string for a number and a float for an integer
    (``limit = 5.0``); an integer stays accepted where a float is expected (``time_s = 60``). TOML arrays
    arrive as lists, so the tuple fields take a list (:data:`Names`, :data:`Seeds`) while their items stay strict.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True)


class Limits(_Strict):
    """Per-cell resource limits (enforced by :mod:`albot1.bench.limits`)."""

    time_s: TimeS = 900.0
    memory_mb: MemoryMb = 4096.0


class GridSpec(_Strict):
    """The degradation sweep applied to datasets with reference poses."""

    degradations: Names = ()
    # At least one: an empty list would drop every swept degradation without a word (undegraded_seeds may be
    # empty: a suite of degraded runs only).
    seeds: Seeds = Field((0,), min_length=1)
    undegraded_seeds: Seeds = (0,)

    @field_validator("degradations")
    @classmethod
    def _valid_specs(cls, value: tuple[str, ...]) -> tuple[str, ...]:
        return _check_degradations(value)

    @field_validator("seeds", "undegraded_seeds")
    @classmethod
    def _distinct_seeds(cls, value: tuple[int, ...]) -> tuple[int, ...]:
        return _check_seeds(value)


class MethodEntry(_Strict):
    """One method column of the grid: a registered method (built in or a plugin) with preset and overrides."""

    name: str = Field(min_length=1)
    preset: str = "default"
    set: dict[str, Any] = Field(default_factory=dict)
    label: str | None = None
    time_s: TimeS | None = None
    memory_mb: MemoryMb | None = None
    datasets: Names | None = Field(
        None,
        min_length=1,
        description="globs over dataset names: this entry runs only on the datasets the suite selects that match "
        "one of them (default: on every one); an expensive method runs on the logs it is there for; an empty list "
        "(which would leave the entry out of the grid without a word) is refused",
    )
    allow_failure: bool = Field(
        False,
        description="a cell of this entry that ends with the method's own failure (its error, a crash, its time or "
        "memory limit) is a finding about the method, not a fault of the suite: it is recorded and reported with "
        "its reason like any failure, but does not make `albot1 bench` exit non-zero",
    )

    trajectories: str | None = Field(
        None,
        description="a path with {dataset}: another system's trajectory files, scored instead of run (external)",
    )
    trajectory_format: Literal["tum", "kitti", "carmen"] | None = None

    @model_validator(mode="after")
    def _external_only(self) -> MethodEntry:
        if self.trajectories is None:
            if self.trajectory_format is not None:
                raise ValueError(f"method {self.name!r}: trajectory_format without trajectories")
            return self
        if "{dataset}" not in self.trajectories:
            raise ValueError(
                f"method {self.name!r}: trajectories = {self.trajectories!r} has no {{dataset}}; expected one file "
                f"per dataset, e.g. 'runs/{self.name}/{{dataset}}.tum'"
            )
        ran = [k for k in ("preset", "set") if k in self.model_fields_set]
        if ran:
            raise ValueError(
                f"method {self.name!r}: {', '.join(ran)} cannot go with trajectories (the files are scored, "
                "nothing is run)"
            )
        return self

    @property
    def display(self) -> str:
        """The column name in reports: the label, else ``name`` or ``name:preset``."""
        if self.trajectories is not None:
            return f"{self.label or self.name} (external)"
        if self.label:
            return self.label
        return self.name if self.preset == "default" else f"{self.name}:{self.preset}"

    def runs_on(self, dataset: str) -> bool:
        """Whether this entry runs on ``dataset`` (a name or reference the suite selected)."""
        return self.datasets is None or any(fnmatch.fnmatchcase(dataset, pattern) for pattern in self.datasets)


class DatasetEntry(_Strict):
    """Options for the datasets whose names match ``name`` (glob, name or path)."""

    name: str = Field(min_length=1)
    skip: bool = False
    optional: bool = Field(
        False,
        description="a literal name or path that cannot be found, or a glob that matches nothing, is skipped, "
        "not an error of the suite",
    )
    limit: int | None = Field(None, ge=1, description="use the first LIMIT scans of the log")
    stride: int | None = Field(None, ge=1, description="then every STRIDE-th of them")
    sweep: bool | Literal["auto"] = "auto"
    degradations: Names | None = None
    seeds: Seeds | None = Field(None, min_length=1)
    undegraded_seeds: Seeds | None = None
    time_s: TimeS | None = None
    memory_mb: MemoryMb | None = None
    methods: Names | None = Field(
        None,
        min_length=1,
        description="labels of the method entries that run on these datasets (default: every entry); a suite "
        "that asks different questions of different data keeps its grid small this way (an empty list is "
        "refused: `skip = true` leaves datasets out)",
    )
    tags: Names = Field(
        (),
        description="names a report finds this entry's datasets by (the thesis page's experiments); they change no run",
    )

    @field_validator("sweep", mode="before")
    @classmethod
    def _sweep_type(cls, value: object) -> object:
        """One problem for a bad ``sweep``, not one per member of ``bool | "auto"``."""
        if isinstance(value, bool) or value == "auto":
            return value
        raise PydanticCustomError("sweep_type", 'Input should be true, false or "auto"')

    @field_validator("degradations")
    @classmethod
    def _valid_specs(cls, value: tuple[str, ...] | None) -> tuple[str, ...] | None:
        return None if value is None else _check_degradations(value)

    @field_validator("seeds", "undegraded_seeds")
    @classmethod
    def _distinct_seeds(cls, value: tuple[int, ...] | None) -> tuple[int, ...] | None:
        return _check_seeds(value)

    @property
    def is_pattern(self) -> bool:
        """Whether ``name`` is a glob; a trailing slice (``NAME[:N]``) is part of a literal reference."""
        text = self.name
        while (stripped := _TRAILING_SLICE.sub("", text)) != text:
            text = stripped
        return any(ch in GLOB_CHARS for ch in text)

    def matches(self, name: str) -> bool:
        return fnmatch.fnmatchcase(name, self.name) if self.is_pattern else name == self.name


class DatasetOptions(_Strict):
    """The merged options of one concrete dataset (all entries that match it, in order)."""

    name: str
    optional: bool = False
    limit: int | None = None
    stride: int | None = None
    sweep: bool | Literal["auto"] = "auto"
    degradations: tuple[str, ...] | None = None
    seeds: tuple[int, ...] | None = None
    undegraded_seeds: tuple[int, ...] | None = None
    time_s: float | None = None
    memory_mb: float | None = None
    methods: tuple[str, ...] | None = None

    @property
    def label(self) -> str:
        """Name plus the slice actually used, e.g. ``intel[:4000:2]``: it is part of the run's identity.

        In the one spelling of :func:`~albot1.data.open.canonical_reference`, so that ``intel[:300]``,
        ``intel[:300:1]``, ``intel[0:300]`` and ``intel`` with ``limit = 300`` name one run key and one run
        folder (each spelling used to compute the same cells again under a key of its own).
        """
        text = self.name + slice_reference("", self.limit, self.stride)
        try:
            return canonical_reference(text)
        except SliceError:  # a slice its dataset refuses: planning stops on it before any cell is labelled
            return text


class Suite(_Strict):
    """A validated suite file."""

    name: str
    description: str = ""
    path: Path | None = None
    registered_methods: bool = False
    limits: Limits = Field(default_factory=Limits)
    grid: GridSpec = Field(default_factory=GridSpec)
    methods: Annotated[tuple[MethodEntry, ...], Strict(False)] = Field(min_length=1)
    datasets: Annotated[tuple[DatasetEntry, ...], Strict(False)] = Field(min_length=1)

    @model_validator(mode="before")
    @classmethod
    def _no_imports(cls, data: Any) -> Any:
        """A suite names methods; it never names code to import (an installed plugin does that)."""
        methods = data.get("methods") if isinstance(data, dict) else None
        for index, entry in enumerate(methods if isinstance(methods, list) else ()):
            named = [key for key in REMOVED_METHOD_KEYS if isinstance(entry, dict) and key in entry]
            if named:
                raise ValueError(
                    f"methods.{index} ({entry.get('name')!r}): `{named[0]}` is not read: a suite names registered "
                    "methods only and imports no module; a mapper of your own registers through the entry point "
                    "group albot1.methods (docs/benchmarking.md)"
                )
        return data

    @field_validator("name")
    @classmethod
    def _plain_name(cls, value: str) -> str:
        if SUITE_NAME.fullmatch(value) is None:
            raise ValueError(
                f"suite name {value!r}: expected a plain folder name of at most 100 letters, digits, '_', '.' or "
                "'-', not starting with '.' (it names the results folder RESULTS/<name>)"
            )
        return value

    @model_validator(mode="after")
    def _unique_labels(self) -> Suite:
        seen: set[str] = set()
        for entry in self.methods:
            if entry.display in seen:
                raise ValueError(f"two method entries are both labelled {entry.display!r}; give one a `label`")
            seen.add(entry.display)
        for index, dataset in enumerate(self.datasets):
            unknown = [label for label in dataset.methods or () if label not in seen]
            if unknown:
                raise ValueError(
                    f"dataset entry {index} ({dataset.name!r}): methods {', '.join(map(repr, unknown))} name no "
                    f"method entry; expected labels among {', '.join(map(repr, seen))}"
                )
        return self

    def options_for(self, name: str) -> DatasetOptions | None:
        """Merged options of dataset ``name``, or None when no entry selects it (or one skips it)."""
        merged: dict[str, Any] = {}
        selected = False
        for entry in self.datasets:
            if not entry.matches(name):
                continue
            if entry.skip:
                selected = False
                merged = {}
                continue
            selected = True
            for field_name in entry.model_fields_set - {"name", "skip", "tags"}:
                merged[field_name] = getattr(entry, field_name)
        return DatasetOptions(name=name, **merged) if selected else None

    def literal_datasets(self) -> list[str]:
        """Dataset names or paths given literally (not as patterns), in suite order."""
        out: list[str] = []
        for entry in self.datasets:
            if not entry.is_pattern and not entry.skip and entry.name not in out:
                out.append(entry.name)
        return out


_Seeds = TypeVar("_Seeds", tuple[int, ...], tuple[int, ...] | None)


def _check_degradations(specs: tuple[str, ...]) -> tuple[str, ...]:
    """Each spec valid, and none twice: a repeated one, or one written two ways (``gauss:0.05:2`` and
    ``gauss:0.050:2.0``), would plan its cells twice, and a report would weight its seeds twice.

    Returned in their canonical spelling (``Degradation.spec``), as ``albot1 run`` records them: ``GAUSS:0.10:1``
    in a suite and ``gauss:0.1:1`` on the command line are one level, one run key and one table row.
    """
    seen: dict[object, str] = {}
    for spec in specs:
        try:
            parsed = parse_spec(spec)
        except DegradationSpecError as exc:
            raise ValueError(str(exc)) from None
        if parsed in seen:
            raise ValueError(f"{spec!r} repeats {seen[parsed]!r} (the same perturbation): list each once")
        seen[parsed] = spec
    return tuple(parse_spec(spec).spec for spec in specs)


def _check_seeds(seeds: _Seeds) -> _Seeds:
    """No seed twice: a repeated seed plans the same cell twice and would be counted twice in a mean."""
    listed = seeds or ()
    repeated = sorted({seed for seed in listed if listed.count(seed) > 1})
    if repeated:
        raise ValueError(f"seed(s) {', '.join(map(str, repeated))} listed more than once: list each seed once")
    return seeds


def parse_suite(
    data: dict[str, Any], *, name: str, source: str, path: Path | None = None, text: str | None = None
) -> Suite:
    """Validate suite data (a parsed TOML table); SuiteError names ``source`` and the offending key.

    ``text``: the file's TOML text, so the error also names the line of the first key it can place
    (``s.toml:12: invalid suite: datasets.3.colour: ...``): in a suite of many ``[[datasets]]`` entries an
    index alone left the user counting headers.
    """
    lines = key_lines(text) if text is not None else {}
    if "path" in data:  # set from where the file was found, never by the file
        at = _at(source, lines, ("path",))
        raise SuiteError(f"{at}: invalid suite: path: unknown key (the suite's path is where its file is)")
    try:
        return Suite.model_validate({"name": name, **data, "path": path})
    except ValidationError as exc:
        located = (error["loc"] for error in exc.errors() if error["loc"])
        at = _at(source, lines, next(located, ()))
        raise SuiteError(f"{at}: invalid suite: {describe_errors(exc, found=True)}") from None


def _at(source: str, lines: dict[tuple[str | int, ...], int], location: tuple[str | int, ...]) -> str:
    """``source:LINE`` when ``location`` (or a prefix of it) has a known line, else ``source``."""
    line = line_of(lines, location) if location else None
    return source if line is None else f"{source}:{line}"


def load_suite(path: str | Path) -> Suite:
    """Read and validate a suite file."""
    file = Path(path)
    try:
        text = file.read_text(encoding="utf-8")
        data = tomllib.loads(text)
    except OSError as exc:
        raise SuiteError(f"{file}: cannot read the suite file: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise SuiteError(f"{file}: not UTF-8 text (byte {exc.start}); expected a TOML suite file") from None
    except tomllib.TOMLDecodeError as exc:
        raise SuiteError(f"{file}: not valid TOML: {exc}") from None
    name = data.pop("name", file.stem)
    return parse_suite(data, name=name, source=str(file), path=file.resolve(), text=text)


def find_suite(ref: str) -> Path:
    """A suite argument -> its file: an existing path, else the project's ``benchmarks/<ref>.toml``.

    Suites by name are found with :func:`albot1.resources.list_resources`
    (a user's ``ALBOT1_CONFIG_DIR/benchmarks/`` first, then the checkout's
    or the installed package's copy).
    """
    candidate = Path(ref).expanduser()
    if candidate.suffix == ".toml" or candidate.is_file():
        if not candidate.is_file():
            raise SuiteError(f"{candidate}: suite file not found")
        return candidate
    suites = {path.stem: path for path in list_resources("benchmarks")}
    if ref not in suites:
        searched = " or ".join(str(folder) for folder in resource_dirs("benchmarks"))
        raise SuiteError(
            f"no suite named {ref!r} in {searched}; expected one of: {', '.join(suites) or '(none)'} "
            "or a path to a .toml file"
        )
    return suites[ref]
