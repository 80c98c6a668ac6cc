"""The method registry: names -> mapper classes (imported lazily) and the
resolution of a typed config from preset, config file and overrides.

Config precedence (lowest first): the config model's defaults, the preset,
environment variables ``ALBOT1_<METHOD>_<FIELD>`` (method and field upper-case,
dashes as underscores; e.g. ``ALBOT1_KISS_ICP_VOXEL_SIZE=0.2``), then
explicit overrides (CLI ``--set FIELD=VALUE`` or a bench suite).
"""

from __future__ import annotations

import importlib
import importlib.util
import os
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel, ValidationError

from albot1.errors import ConfigError
from albot1.runs.errors import UnknownMethodError


@dataclass(frozen=True)
class MethodSpec:
    """How to find a method: its class, the imports it needs, its error class."""

    name: str
    target: str  # "module:Class"
    requires: tuple[str, ...] = ()
    error_class: str = "albot1.methods.baselines.errors:BaselineError"
    description: str = ""

    def available(self) -> bool:
        """True when every required import can be found (without importing it)."""
        return all(importlib.util.find_spec(mod) is not None for mod in self.requires)

    def load_class(self) -> Any:
        if not self.available():
            missing = [m for m in self.requires if importlib.util.find_spec(m) is None]
            raise UnknownMethodError(f"method {self.name!r} needs {', '.join(missing)}, which is not installed")
        module_name, _, attr = self.target.partition(":")
        return getattr(importlib.import_module(module_name), attr)

    def load_error_class(self) -> type[Exception]:
        module_name, _, attr = self.error_class.partition(":")
        return getattr(importlib.import_module(module_name), attr)


METHODS: dict[str, MethodSpec] = {
    spec.name: spec
    for spec in (
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
    )
}


def get_method(name: str) -> MethodSpec:
    try:
        return METHODS[name]
    except KeyError:
        raise UnknownMethodError(f"unknown method {name!r}; expected one of: {', '.join(METHODS)}") from None


def _env_overrides(method: str, model: type[BaseModel]) -> dict[str, str]:
    prefix = "ALBOT1_" + method.upper().replace("-", "_") + "_"
    found = {}
    for field_name in model.model_fields:
        value = os.environ.get(prefix + field_name.upper())
        if value is not None:
            found[field_name] = value
    return found


def resolve_config(method: str, preset: str = "default", overrides: dict[str, Any] | None = None) -> BaseModel:
    """The validated config of ``method`` for ``preset`` plus env and explicit overrides."""
    cls = get_method(method).load_class()
    presets: dict[str, dict[str, Any]] = cls.presets
    if preset not in presets:
        raise ConfigError(f"method {method!r} has no preset {preset!r}; expected one of: {', '.join(presets)}")
    values = {**presets[preset], **_env_overrides(method, cls.config_model), **(overrides or {})}
    try:
        return cls.config_model.model_validate(values)
    except ValidationError as exc:
        problems = "; ".join(f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in exc.errors())
        raise ConfigError(f"invalid config for method {method!r} (preset {preset!r}): {problems}") from None


def parse_overrides(pairs: list[str]) -> dict[str, Any]:
    """``["a=1", "b=x"]`` -> ``{"a": "1", "b": "x"}`` (pydantic converts the strings)."""
    out: dict[str, Any] = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key.strip():
            raise ConfigError(f"override {pair!r} is not of the form FIELD=VALUE")
        out[key.strip()] = value.strip()
    return out
