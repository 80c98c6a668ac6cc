"""The method registry: names -> mapper classes (imported lazily) and the
resolution of a typed config from preset, environment and overrides.

Config precedence (lowest first; :mod:`albot1.config.resolve`): the config
model's defaults, the preset (every method's presets are a TOML file read by
:class:`albot1.config.presets.TomlPresets`), environment variables
``ALBOT1_<METHOD>_<FIELD>`` (method and field upper-case, dashes as
underscores; e.g. ``ALBOT1_KISS_ICP_VOXEL_SIZE_M=0.2``; a variable under a
method's prefix that names no field is an error), then explicit overrides
(CLI ``--set FIELD=VALUE`` or a bench suite's ``set``).
"""

from __future__ import annotations

import functools
import importlib.util
import inspect
import logging
import os
import shutil
import sys
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, cast

from pydantic import BaseModel

from albot1.config.env import method_prefix, stray_variables
from albot1.config.keyvalue import parse_key_values
from albot1.config.resolve import FROM_OVERRIDE, ResolvedConfig, resolve
from albot1.config.suggest import unknown_name_message
from albot1.config.targets import TargetError, check_target, resolve_class
from albot1.methods.errors import MethodUnavailableError, UnknownMethodError
from albot1.methods.plugins import PLUGIN_ERROR_CLASS, installed_plugins

_log = logging.getLogger(__name__)

if TYPE_CHECKING:
    # For the types only: the contract imports the data layer (numpy, the records), which listing the
    # methods (`albot1 methods`) does not need; a mapper class's own module imports it when loaded.
    from albot1.contract import Mapper

#: What a class must define to be run as a mapper (:class:`albot1.contract.Mapper`).
MAPPER_ATTRIBUTES = ("name", "config_model", "presets", "process", "finish")


def load_mapper_class(target: str) -> type[Mapper]:
    """The mapper class named by ``"module:Class"``; TargetError when it is none.

    The check looks the attributes up statically, so a class whose presets
    are read lazily from a file (:class:`~albot1.config.presets.TomlPresets`)
    is not made to read it here.
    """
    cls = resolve_class(target)
    missing = [name for name in MAPPER_ATTRIBUTES if _static_attr(cls, name) is None]
    if missing:
        raise TargetError(f"{target}: not a mapper class, it lacks {', '.join(missing)} (see albot1.contract.Mapper)")
    model = _static_attr(cls, "config_model")
    if not (isinstance(model, type) and issubclass(model, BaseModel)):
        raise TargetError(
            f"{target}: its config_model is {model!r}; expected a pydantic BaseModel subclass "
            "(see albot1.contract.Mapper)"
        )
    return cast("type[Mapper]", cls)


def _static_attr(cls: type, name: str) -> object | None:
    try:
        found: object = inspect.getattr_static(cls, name)
        return found
    except AttributeError:
        return None


@dataclass(frozen=True)
class MethodSpec:
    """How to find a method: its class, the imports and programs it needs, its error class.

    ``executables`` are external programs the method runs (looked up on
    ``PATH``); ``install_hint`` is the command that installs them, shown
    when they are missing. ``auto_include`` says whether a suite's
    ``registered_methods = true`` adds the method: an external system whose
    runs cost minutes per log runs only where a suite names it.
    """

    name: str
    target: str  # "module:Class"
    requires: tuple[str, ...] = ()
    error_class: str = "albot1.methods.baselines.errors:BaselineError"
    description: str = ""
    executables: tuple[str, ...] = ()
    install_hint: str = ""
    auto_include: bool = True
    #: True when the method's output depends on its seed even on undegraded odometry (a particle filter):
    #: the bench then runs every seed under a deterministic degradation too, instead of the first only.
    stochastic: bool = False
    #: True when the method does its work in ``finish`` (a batch program given the whole log): each ``process``
    #: call only keeps its frame, so the per-scan times are that bookkeeping, not the method's cost, and the run
    #: records its per-scan statistics as not applicable (``timing.per_scan_reason``; its cost is ``total_s``).
    batch: bool = False
    #: The distribution that declares the method (an installed plugin), None for a method of this package,
    #: whose presets are the file ``baselines/<name>.toml`` (:func:`albot1.config.presets.preset_names`).
    plugin: str | None = None

    def __post_init__(self) -> None:
        check_target(self.target)
        check_target(self.error_class)

    def missing_modules(self) -> list[str]:
        """Required imports that cannot be found (without importing them)."""
        return [mod for mod in self.requires if importlib.util.find_spec(mod) is None]

    def missing_executables(self) -> list[str]:
        """Required programs that are not on ``PATH``."""
        return [exe for exe in self.executables if shutil.which(exe) is None]

    def available(self) -> bool:
        """True when every required import and program can be found."""
        return not self.missing_modules() and not self.missing_executables()

    def unavailable_reason(self) -> str | None:
        """Why the method cannot run here (one line), or None when it can."""
        parts = []
        modules, programs = self.missing_modules(), self.missing_executables()
        if modules:
            parts.append(f"needs {', '.join(modules)}, which is not installed")
        if programs:
            parts.append(f"needs the program(s) {', '.join(programs)}, not found on PATH")
        return "; ".join(parts) if parts else None

    def install_command(self) -> str:
        """The command that installs what is missing (``install_hint``, else ``pip install`` of the modules)."""
        if self.install_hint:
            return self.install_hint
        modules = self.missing_modules()
        return f"pip install {' '.join(modules)}" if modules else ""

    def load_class(self) -> type[Mapper]:
        reason = self.unavailable_reason()
        if reason is not None:
            hint = self.install_command()
            raise MethodUnavailableError(
                f"method {self.name!r} is unavailable: {reason}" + (f" (install: {hint})" if hint else "")
            )
        try:
            return load_mapper_class(self.target)
        except TargetError as exc:  # say which method (and which plugin's) it is, not only its class
            origin = f" (plugin of {self.plugin})" if self.plugin is not None else ""
            raise TargetError(f"method {self.name!r}{origin}: {exc}") from exc

    def program_versions(self) -> dict[str, str | None]:
        """The versions of the programs outside Python the method runs (its class's ``program_versions``), else {}.

        Read by the planner for each cell's key (:func:`albot1.versions.run_versions`); raises as
        :meth:`load_class` does, and ValueError naming the method when they could not be recorded.
        """
        from albot1 import versions  # here: listing the methods (`albot1 run --help`) reads no version

        read = getattr(self.load_class(), "program_versions", None)
        found = read() if callable(read) else {}
        problem = versions.program_versions_problem(found)
        if problem is not None:
            raise ValueError(f"method {self.name!r}: program_versions(): {problem}")
        return dict(found)

    def load_error_class(self) -> type[Exception]:
        cls = resolve_class(self.error_class)
        if not issubclass(cls, Exception):
            raise TargetError(f"{self.error_class}: expected an exception class for method {self.name!r}")
        return cls

    @property
    def env_prefix(self) -> str:
        """``ALBOT1_<METHOD>_``: the prefix of this method's environment variables."""
        return method_prefix(self.name)


#: The methods of this package, in the order listings show them.
BUILTIN_METHODS: tuple[MethodSpec, ...] = (
    MethodSpec(
        "odometry",
        "albot1.methods.baselines.odometry:OdometryMapper",
        description="dead reckoning: the (possibly degraded) odometry, scans projected with it",
    ),
    MethodSpec(
        "albot1",
        "albot1.methods.albot1.mapping.mapper:Albot1Mapper",
        error_class="albot1.methods.albot1.mapping.errors:MappingError",
        description="the Albot1 perceptual mapper (thesis chapter 3)",
    ),
    MethodSpec(
        "albot1-places",
        "albot1.methods.albot1.places.mapper:Albot1PlacesMapper",
        requires=("networkx",),
        error_class="albot1.methods.albot1.mapping.errors:MappingError",
        description="Albot1 with its network of places (thesis chapter 4: exits, places, re-visits, exit aid)",
    ),
    MethodSpec(
        "kiss-icp",
        "albot1.methods.baselines.kiss_icp:KissIcpMapper",
        requires=("kiss_icp",),
        description="KISS-ICP odometry on planar scans, odometry as initial guess",
    ),
    MethodSpec(
        "gtsam-graph",
        "albot1.methods.baselines.gtsam_graph:GtsamGraphMapper",
        requires=("gtsam",),
        description="graph SLAM: scan-matching edges, loop closures, ISAM2 + final LM (GTSAM)",
    ),
    MethodSpec(
        "mrpt-icp",
        "albot1.methods.baselines.mrpt:MrptIcpMapper",
        executables=("icp-slam",),
        batch=True,
        install_hint="apt-get install mrpt-apps (or: make mrpt)",
        auto_include=False,
        description="MRPT icp-slam: incremental ICP scan matching against a point map, no loop closing",
    ),
    MethodSpec(
        "mrpt-rbpf",
        "albot1.methods.baselines.mrpt:MrptRbpfMapper",
        executables=("rbpf-slam",),
        batch=True,
        stochastic=True,
        install_hint="apt-get install mrpt-apps (or: make mrpt)",
        auto_include=False,
        description="MRPT rbpf-slam: Rao-Blackwellized particle filter grid SLAM (GMapping family)",
    ),
)


@dataclass(frozen=True)
class MethodRegistry:
    """Method names -> specs, immutable: built once (:func:`method_registry`) and handed to whoever runs methods.

    The planner and every cell read the same registry instead of writing
    into a module global; a test builds its own with :meth:`with_methods`.
    """

    specs: Mapping[str, MethodSpec]

    def __post_init__(self) -> None:
        object.__setattr__(self, "specs", MappingProxyType(dict(self.specs)))

    @classmethod
    def of(cls, specs: Iterable[MethodSpec]) -> MethodRegistry:
        """A registry of ``specs``; a name given twice is a ConfigError."""
        out: dict[str, MethodSpec] = {}
        for spec in specs:
            if spec.name in out:
                raise UnknownMethodError(
                    f"method {spec.name!r} is registered twice ({out[spec.name].target} and {spec.target})"
                )
            out[spec.name] = spec
        return cls(out)

    def with_methods(self, *specs: MethodSpec) -> MethodRegistry:
        """A new registry with ``specs`` added or replacing those of the same name (this one is unchanged)."""
        return MethodRegistry({**self.specs, **{spec.name: spec for spec in specs}})

    def names(self) -> list[str]:
        return list(self.specs)

    def __contains__(self, name: object) -> bool:
        return name in self.specs

    def __iter__(self) -> Iterator[MethodSpec]:
        return iter(self.specs.values())

    def __len__(self) -> int:
        return len(self.specs)

    def get(self, name: str) -> MethodSpec:
        """The spec of ``name``; UnknownMethodError (one line, with the closest names) otherwise."""
        try:
            return self.specs[name]
        except KeyError:
            raise UnknownMethodError(unknown_name_message("method", name, self.names())) from None

    def other_prefixes(self, method: str) -> list[str]:
        """The environment prefixes of every method but ``method`` (see :func:`resolve_method_config`)."""
        return [spec.env_prefix for spec in self if spec.name != method]


#: The import path, each folder with its modification time, when :func:`method_registry` last read the plugins.
_read_from: tuple[tuple[str, int | None], ...] | None = None


def _modified(path: str) -> int | None:
    """``path``'s modification time (ns), None where it cannot be read."""
    try:
        return os.stat(path).st_mtime_ns
    except OSError:
        return None


def _path_state() -> tuple[tuple[str, int | None], ...]:
    """Each ``sys.path`` entry and each distribution's ``entry_points.txt`` in it, with its modification time."""
    state: list[tuple[str, int | None]] = []
    for entry in sys.path:
        folder = entry or "."
        state.append((entry, _modified(folder)))
        try:
            names = sorted(e.name for e in os.scandir(folder) if e.name.endswith((".dist-info", ".egg-info")))
        except OSError:
            continue
        state += [(name, _modified(os.path.join(folder, name, "entry_points.txt"))) for name in names]
    return tuple(state)


def forget_registry_if_changed() -> None:
    """Read the plugins again on the next :func:`method_registry` unless nothing they are found in has changed.

    Why: a bench cell is forked from a server that read the registry when it started, and a plugin may have
    been installed since (the cell then reads it again). Reading the entry points means reading and parsing every
    installed distribution's metadata (~17 ms of CPU per cell, issue 24); looking at their times is a few stats.
    Installing, removing or reinstalling a distribution adds or removes an entry in a folder on the import path,
    which changes that folder's modification time (the test :mod:`importlib.metadata` itself makes before it
    lists a folder again); an ``entry_points.txt`` rewritten in place (a legacy editable install run again)
    changes its own. So the registry is kept when the import path, each folder on it and each distribution's
    ``entry_points.txt`` have the times they had when it was read. (The file system's times are a few
    milliseconds coarse: a change in the same tick as the reading is missed, as by :mod:`importlib.metadata`.)
    """
    if _read_from is None or _path_state() != _read_from:
        method_registry.cache_clear()


@functools.cache
def method_registry() -> MethodRegistry:
    """The registry of this process: the built-in methods and the installed plugins, read once.

    Plugins are the entry points of group ``albot1.methods``
    (:mod:`albot1.methods.plugins`); reading them imports nothing.
    """
    global _read_from
    _read_from = _path_state()  # before reading: a change made while it reads is seen by the next check
    plugins = [
        MethodSpec(
            p.name,
            p.target,
            error_class=PLUGIN_ERROR_CLASS,
            # its top-level module, found without importing it: a distribution whose code is gone is unavailable
            requires=(p.target.partition(":")[0].split(".")[0],),
            install_hint=f"reinstall {p.source.split()[0]}, which declares it",
            auto_include=False,  # a suite runs an installed plugin where it names it
            description=f"plugin {p.target} from {p.source}",
            plugin=p.source,
        )
        for p in installed_plugins(spec.name for spec in BUILTIN_METHODS)
    ]
    return MethodRegistry.of([*BUILTIN_METHODS, *plugins])


def get_method(name: str, registry: MethodRegistry | None = None) -> MethodSpec:
    """The spec of ``name`` in ``registry`` (default: :func:`method_registry`)."""
    return (registry or method_registry()).get(name)


def resolve_method_config(
    method: str,
    preset: str = "default",
    overrides: dict[str, Any] | None = None,
    registry: MethodRegistry | None = None,
    override_origin: str = FROM_OVERRIDE,
    typed_overrides: bool = False,
) -> ResolvedConfig[BaseModel]:
    """The validated config of ``method`` for ``preset`` plus env and explicit overrides, with each value's origin.

    ``override_origin``: where ``overrides`` came from, as messages name it (default ``--set``);
    ``typed_overrides``: they are typed TOML values, validated as written (:func:`albot1.config.resolve.resolve`).

    Environment variables of the other registered methods are left to them:
    with nested prefixes (``albot1`` and a method ``albot1-places``) a
    variable belongs to the longest prefix it starts with.
    """
    registry = registry or method_registry()
    spec = registry.get(method)
    cls = spec.load_class()
    _say_stray_variables(registry, spec, cls.config_model)
    return resolve(
        cls.config_model,
        cls.presets,
        preset,
        env_prefix=spec.env_prefix,
        other_prefixes=registry.other_prefixes(method),
        overrides=overrides,
        owner=method,
        override_origin=override_origin,
        typed_overrides=typed_overrides,
    )


def _say_stray_variables(registry: MethodRegistry, spec: MethodSpec, model: type[BaseModel]) -> None:
    """Warn, once per process and variable, about ``ALBOT1_`` variables no method or setting reads.

    The hint names the closest of this method's variables and the settings
    (loading every method's model for it would import them all).
    """
    prefixes = [other.env_prefix for other in registry]
    valid = [spec.env_prefix + name.upper() for name in model.model_fields]
    for variable, message in stray_variables([v for v in os.environ if v not in _said_stray], prefixes, valid):
        _said_stray.add(variable)
        _log.warning("%s", message)


_said_stray: set[str] = set()


def resolve_config(
    method: str,
    preset: str = "default",
    overrides: dict[str, Any] | None = None,
    registry: MethodRegistry | None = None,
    override_origin: str = FROM_OVERRIDE,
    typed_overrides: bool = False,
) -> BaseModel:
    """The validated config of ``method`` (see :func:`resolve_method_config`)."""
    return resolve_method_config(method, preset, overrides, registry, override_origin, typed_overrides).config


def parse_overrides(pairs: list[str]) -> dict[str, str]:
    """``["a=1", "b=x"]`` -> ``{"a": "1", "b": "x"}`` (pydantic converts the strings)."""
    return parse_key_values(pairs, what="override", key="FIELD")
