"""Expand a suite into the cells that run on this machine.

Datasets that are not downloaded and methods whose libraries are missing are
*skipped* with the command that fixes it, never failed: a fresh machine must
still produce a complete report from the synthetic worlds. A method entry
whose config does not resolve (a preset the method lacks, an override it
rejects) is an error of the suite, raised before any cell runs (``--dry-run``
included). A method whose class does not load (a plugin module that does not
import) is not skipped: its cells are planned and recorded as failed with the
reason, so the report shows the problem next to the results that did run.
"""

from __future__ import annotations

import fnmatch
import os
import platform
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from albot1 import versions
from albot1.bench.errors import SuiteError
from albot1.bench.external import external_cell, one_log_per_file
from albot1.bench.grid import Cell, GridPlan, Skipped
from albot1.bench.suite import DatasetOptions, MethodEntry, Suite
from albot1.config.suggest import unknown_name_message
from albot1.config.targets import TargetError
from albot1.data import catalog
from albot1.data.degrade import parse_spec
from albot1.data.errors import DatasetNotFoundError
from albot1.data.model import SequenceMetadata
from albot1.data.open import open_sequence, split_slice
from albot1.data.synthetic import worlds
from albot1.errors import Albot1Error, ConfigError
from albot1.methods.plugins import ENTRY_POINT_GROUP
from albot1.methods.registry import MethodRegistry, MethodSpec, method_registry, resolve_config
from albot1.runs.folder import run_key
from albot1.settings import Settings


def machine_info(programs: Mapping[str, str | None] | None = None) -> dict[str, Any]:
    """What the report states about where the numbers were measured.

    ``libraries``: the recorded libraries' versions, and those of the programs the planned cells run
    (``programs``, MRPT's): the versions every planned cell's key names, so every result the report shows,
    kept or new, was computed with them.
    """
    import psutil

    return {
        "cpu_count": os.cpu_count(),
        "cpu_count_physical": psutil.cpu_count(logical=False),
        "memory_gb": round(psutil.virtual_memory().total / 2**30, 1),
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_model": cpu_model(),
        "python": sys.version.split()[0],
        "code_version": versions.code_version(),
        "git": versions.git_commit(),
        "libraries": {**versions.library_versions(), **(programs or {})},
    }


def cpu_model() -> str:
    """The CPU's model name (Linux ``/proc/cpuinfo``), else what :mod:`platform` knows; timings are tied to it."""
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace").splitlines():
            if line.lower().startswith("model name") and ":" in line:
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _resolve(suite: Suite, entry: MethodEntry, registry: MethodRegistry) -> tuple[dict[str, Any] | None, str | None]:
    """(resolved config as JSON, None) or (None, reason the method's class does not load).

    The config is resolved by :func:`~albot1.methods.registry.resolve_config`, the validation every run
    does (:func:`albot1.runs.execute.run_method`). A preset the method does not have, an override it
    rejects (an unknown key, a bad value) or a variable under its environment prefix that names no field
    is a SuiteError naming the file and the entry: every cell of the entry would fail the same way, and
    ``--dry-run`` must say so. A class that does not load (a plugin whose module does not import) is the
    method's fault, not the suite's: its cells are recorded as failed with the reason.
    """
    try:
        registry.get(entry.name).load_class()
    except TargetError as exc:  # its message names the method (and the plugin declaring it)
        return None, f"cannot load {exc}"
    except Exception as exc:  # the method's module itself is broken: a cell failure, not a runner crash
        return None, f"cannot load method {entry.name!r}: {type(exc).__name__}: {exc}"
    try:
        config = resolve_config(
            entry.name, entry.preset, dict(entry.set), registry, override_origin="set", typed_overrides=True
        )
    except ConfigError as exc:
        where = (
            f"methods.{suite.methods.index(entry)} ({entry.display!r})"
            if entry in suite.methods
            else f"method {entry.display!r} (added by registered_methods = true)"
        )
        raise SuiteError(f"{suite.path or suite.name}: invalid suite: {where}: {exc}") from None
    except Exception as exc:  # the method's config model itself is broken
        return None, f"cannot resolve the config of method {entry.name!r}: {type(exc).__name__}: {exc}"
    return config.model_dump(mode="json"), None


def _program_versions(spec: MethodSpec) -> tuple[dict[str, str | None], str | None]:
    """The versions of the programs a cell of ``spec`` will run (in its key), and why the cell cannot run.

    Read once per method and plan (:meth:`MethodSpec.program_versions`; the MRPT mapper keeps its answer while
    the executable is the same file), for a method of which an entry resolved (the others fail with their own
    reason). A method whose ``program_versions`` fails is keyed without them, and its cells fail with the reason.
    """
    try:
        return spec.program_versions(), None
    except Exception as exc:  # a plugin's program_versions is broken: a cell failure, not a runner crash
        return {}, f"cannot read the program versions of method {spec.name!r}: {type(exc).__name__}: {exc}"


def _methods(suite: Suite, registry: MethodRegistry) -> tuple[list[MethodEntry], list[Skipped]]:
    entries = [e for e in suite.methods if e.trajectories is None]
    external = [e for e in suite.methods if e.trajectories is not None]  # scored files: nothing to install
    for entry in external:
        if entry.name in registry:
            raise SuiteError(
                f"{suite.path or suite.name}: method {entry.name!r} with trajectories: {entry.name!r} is a method "
                f"this project runs; name another system's output differently (e.g. {entry.name + '-theirs'!r})"
            )
    for entry in entries:
        if entry.name not in registry:
            raise SuiteError(
                f"{suite.path or suite.name}: {unknown_name_message('method', entry.name, registry.names())} "
                f"(a suite names registered methods only; a third-party method registers through the entry point "
                f"group {ENTRY_POINT_GROUP}, see docs/benchmarking.md)"
            )
    if suite.registered_methods:
        named = {e.name for e in entries}
        entries += [MethodEntry(name=spec.name) for spec in registry if spec.name not in named and spec.auto_include]
    usable, skipped = [], []
    for entry in entries:
        spec = registry.get(entry.name)
        if spec.available():
            usable.append(entry)
        else:
            skipped.append(Skipped(entry.display, f"unavailable: {spec.unavailable_reason()}", spec.install_command()))
    return usable + external, skipped


def _candidate_datasets(suite: Suite) -> list[str]:
    """The dataset names and references the suite selects; SuiteError for a glob that matches none of them."""
    known = list(worlds.WORLDS) + sorted(catalog.names())
    literals = suite.literal_datasets()
    for index, entry in enumerate(suite.datasets):
        if entry.is_pattern and not entry.optional and not any(entry.matches(n) for n in [*known, *literals]):
            raise SuiteError(
                f"{suite.path or suite.name}: dataset entry {index} ({entry.name!r}) matches no dataset; expected a "
                f"glob over the names {', '.join(known)} (a prefix of every match is `limit = N`), or mark the "
                "entry `optional = true`"
            )
    for method in suite.methods:
        for pattern in method.datasets or ():
            if not any(fnmatch.fnmatchcase(n, pattern) for n in [*known, *literals]):
                raise SuiteError(
                    f"{suite.path or suite.name}: method entry {method.display!r}: datasets pattern {pattern!r} "
                    f"matches no dataset; expected a glob over the names {', '.join(known)} or a dataset entry's"
                    " reference"
                )
    out = [n for n in known if suite.options_for(n) is not None]
    for literal in literals:
        if literal not in out and suite.options_for(literal) is not None:
            out.append(literal)
    return out


def _availability(name: str, settings: Settings) -> tuple[bool | None, Skipped | None, bool, SequenceMetadata]:
    """(has reference poses, None, True, metadata) when the dataset opens, else (None, why skipped, known, empty).

    The metadata's checksums (``SequenceMetadata.checksums``, cached) and manifest loader options go into the
    cells' keys.

    ``known`` is False when ``name`` names nothing that exists (no world, no
    registered dataset, no file, or options its loader rejects): for a
    literal suite entry that is an error unless the entry is ``optional``.
    A registered dataset that is merely not downloaded is known.
    """
    # A sliced reference, or one with loader options, needs its catalog files all the same.
    base = split_slice(name)[0].partition("?")[0]
    if base in catalog.names():
        try:
            catalog.locate(base, settings)
        except DatasetNotFoundError as exc:
            manifest = catalog.get(base)
            fetchable = not manifest.local_only and bool(manifest.log.urls)
            hint = f"albot1 datasets fetch {base}" if fetchable else ""
            return None, Skipped(name, f"not downloaded: {exc}", hint), True, SequenceMetadata()
    try:
        sequence = open_sequence(name, settings=settings)
        first = next(iter(sequence.frames()), None)
    except DatasetNotFoundError as exc:
        return None, Skipped(name, str(exc)), False, SequenceMetadata()
    if first is None:
        return None, Skipped(name, "the dataset holds no scans"), True, SequenceMetadata()
    return first.reference is not None, None, True, sequence.metadata


def _deterministic(degradation: str) -> bool:
    """True when a degradation ignores its seed (every seed would repeat one run)."""
    return not parse_spec(degradation).seeded


def _sweep(opts: DatasetOptions, suite: Suite, has_reference: bool) -> list[tuple[str, tuple[int, ...]]]:
    """(degradation, seeds) of a dataset entry; the caller keeps one seed where nothing depends on it."""
    grid = suite.grid
    undegraded = opts.undegraded_seeds if opts.undegraded_seeds is not None else grid.undegraded_seeds
    runs = [("none", tuple(undegraded))]
    sweep = has_reference if opts.sweep == "auto" else bool(opts.sweep)
    if sweep:
        degradations = opts.degradations if opts.degradations is not None else grid.degradations
        seeds = opts.seeds if opts.seeds is not None else grid.seeds
        runs += [(d, tuple(seeds)) for d in degradations if d != "none"]
    return runs


def _no_runs(opts: DatasetOptions, suite: Suite, has_reference: bool) -> str:
    """Why a dataset that opened plans no run: no undegraded seed, and no degradation swept on it.

    Such a dataset used to vanish from the grid without a word (and a suite of only such datasets
    ended in "every dataset or method it selects was skipped", naming none).
    """
    if opts.sweep == "auto" and not has_reference:
        why = 'no degradation is swept on it (sweep = "auto" and it has no reference poses)'
    elif opts.sweep is False:
        why = "no degradation is swept on it (sweep = false)"
    elif opts.degradations if opts.degradations is not None else suite.grid.degradations:
        why = "its degradations list names only `none` (the undegraded run, which has no seed here)"
    else:
        why = "its degradations list is empty"
    return f"no cell planned: undegraded_seeds is empty and {why}"


def _runs_once(degradation: str, method: str, registry: MethodRegistry) -> bool:
    """A deterministic degradation of a deterministic method runs with the first seed only.

    The first seed keeps the run key such a cell always had, so stored results stay found; a
    stochastic method (its registry entry says so) keeps every seed, since its output varies with it.
    """
    return _deterministic(degradation) and not (method in registry and registry.get(method).stochastic)


def _limit(*values: float | None, default: float) -> float:
    given = [v for v in values if v is not None]
    return max(given) if given else default


def _check_shared_folders(suite: Suite, cells: list[Cell]) -> None:
    """SuiteError when two cells share a run folder (same inputs) but not their limits.

    Two labels for the same inputs share one folder and one result (the
    runner runs the cell once). Limits are not inputs of the result, so they
    are not in the key; cells that differ only in their limits would
    silently run under the first cell's limits and report its outcome for both.
    """
    first: dict[str, Cell] = {}
    for cell in cells:
        other = first.setdefault(cell.key, cell)
        if (other.time_s, other.memory_mb) != (cell.time_s, cell.memory_mb):
            raise SuiteError(
                f"{suite.path or suite.name}: {other.describe()} (time_s {other.time_s:g}, memory_mb "
                f"{other.memory_mb:g}) and {cell.describe()} (time_s {cell.time_s:g}, memory_mb {cell.memory_mb:g}) "
                "are the same run (same dataset slice, method, config, degradation and seed) with different limits; "
                "one run folder holds one outcome: give them the same limits, or make them differ in what they run"
            )


def plan_suite(suite: Suite, settings: Settings, registry: MethodRegistry | None = None) -> GridPlan:
    """The cells of ``suite`` on this machine (datasets present, methods installed).

    ``registry`` (default: :func:`~albot1.methods.registry.method_registry`)
    is only read; the cells read the same one in their own processes.
    """
    registry = registry or method_registry()
    code = versions.code_version()
    methods, skipped_methods = _methods(suite, registry)
    resolved = {entry.display: _resolve(suite, entry, registry) for entry in methods if entry.trajectories is None}
    # method name -> (its programs' versions, why they cannot be read): once per method, for the methods of which
    # an entry resolved (an entry's config problem is its own, not its method's other entries')
    programs_of = {
        name: _program_versions(registry.get(name))
        for name in dict.fromkeys(e.name for e in methods if e.trajectories is None and resolved[e.display][1] is None)
    }
    programs: dict[str, str | None] = {}  # of the methods that have cells, for the report (machine_info)
    cells: list[Cell] = []
    skipped_datasets: list[Skipped] = []
    config_failures: dict[str, str] = {}
    literals = set(suite.literal_datasets())
    external_logs: dict[str, tuple[str, str]] = {}  # an external file -> (its first dataset, that dataset's log)
    for name in _candidate_datasets(suite):
        opts = suite.options_for(name)
        assert opts is not None  # _candidate_datasets keeps selected names only
        try:
            has_reference, skipped, known, metadata = _availability(name, settings)
        except Albot1Error as exc:  # a bad slice or loader option, a log that does not parse
            raise SuiteError(f"{suite.path or suite.name}: dataset {name!r}: {exc}") from None
        if skipped is not None and not known and name in literals and not opts.optional:
            raise SuiteError(
                f"{suite.path or suite.name}: dataset entry {name!r}: {skipped.reason}; "
                "fix the name, or mark the entry `optional = true` to skip it when it is absent"
            )
        if skipped is not None:
            skipped_datasets.append(skipped)
            continue
        runs = _sweep(opts, suite, bool(has_reference))
        if not any(seeds for _, seeds in runs):
            skipped_datasets.append(Skipped(name, _no_runs(opts, suite, bool(has_reference))))
            continue
        for degradation, sweep_seeds in runs:
            for seed, entry in ((s, e) for s in sweep_seeds for e in methods):
                if opts.methods is not None and entry.display not in opts.methods:
                    continue
                if not entry.runs_on(name):
                    continue
                if entry.trajectories is not None:
                    if degradation == "none" and seed == sweep_seeds[0]:
                        cells.append(external_cell(suite, entry, name, opts, seed, metadata))
                        one_log_per_file(suite, entry, cells[-1], metadata, external_logs)
                    continue
                if seed != sweep_seeds[0] and _runs_once(degradation, entry.name, registry):
                    continue
                config, problem = resolved[entry.display]
                ran, versions_problem = programs_of.get(entry.name, ({}, None))
                problem = problem or versions_problem
                # the versions block the cell's run will record (albot1.runs.execute), so its folder is found again
                planned = versions.run_versions(ran, registry.get(entry.name).plugin)
                key_config = (
                    config
                    if config is not None
                    else {"unresolved": True, "preset": entry.preset, "set": dict(entry.set)}
                )
                key = run_key(
                    opts.label,
                    entry.name,
                    key_config,
                    degradation,
                    seed,
                    planned,
                    metadata.checksums,
                    metadata.manifest_loader,
                )
                if problem is not None:
                    config_failures[key] = problem
                programs.update(ran)
                cells.append(
                    Cell(
                        suite=suite.name,
                        dataset=name,
                        dataset_label=opts.label,
                        method=entry.name,
                        method_label=entry.display,
                        preset=entry.preset,
                        degradation=degradation,
                        seed=seed,
                        key=key,
                        code_version=code,
                        time_s=_limit(opts.time_s, entry.time_s, default=suite.limits.time_s),
                        memory_mb=_limit(opts.memory_mb, entry.memory_mb, default=suite.limits.memory_mb),
                        limit=opts.limit,
                        stride=opts.stride,
                        overrides=dict(entry.set),
                        config=config,
                        allow_failure=entry.allow_failure,
                        versions=versions.key_versions(planned),
                    )
                )
    _check_shared_folders(suite, cells)
    seeds = sorted({c.seed for c in cells})
    degradations = list(dict.fromkeys(c.degradation for c in cells))
    return GridPlan(
        suite=suite.name,
        suite_path=str(suite.path) if suite.path else None,
        description=suite.description,
        cells=cells,
        skipped_datasets=skipped_datasets,
        skipped_methods=skipped_methods,
        config_failures=config_failures,
        seeds=seeds,
        degradations=degradations,
        machine=machine_info(programs),
    )
