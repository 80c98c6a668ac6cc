"""The CARMEN loader's options: every ``FILE?key=value`` the loader accepts, validated in one place.

:func:`parse_options` splits what the loader is given into the catalog's
fields (``relations``, ``license``, ``citation``), which every loader takes,
and the CARMEN options proper (:class:`CarmenOptions`: pose sources, laser
kind, range limit, time tolerance, name, parallel bzip2), each checked with
a one-line error naming the file, the value found and what was expected.
The describers say in words, for the sequence's metadata, which fields a
chosen pose source reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from albot1.config.suggest import did_you_mean
from albot1.data.errors import DataError
from albot1.data.loaders.base import (
    DEFAULT_MAX_POSE_GAP_S,
    DEFAULT_TIME_TOLERANCE_S,
    max_pose_gap,
    option_names,
    unknown_option_hint,
)
from albot1.data.loaders.carmen.parse import LASER_MESSAGES, OLD_LASERS
from albot1.data.relations import RepeatPolicy, repeat_policy

ODOMETRY_SOURCES = ("laser-pose", "odom", "odom-segments")
REFERENCE_SOURCES = ("none", "laser-pose", "truepos", "auto")


@dataclass(frozen=True)
class CarmenOptions:
    """Validated loader options (see the loader module's docstring)."""

    odometry: str = "laser-pose"
    reference: str = "auto"
    laser: str | None = None
    max_range: float | None = None
    time_tolerance: float = DEFAULT_TIME_TOLERANCE_S
    #: largest gap (s) between the ODOM/TRUEPOS lines a scan's pose is interpolated between (loaders/base.py)
    max_pose_gap: float = DEFAULT_MAX_POSE_GAP_S
    name: str | None = None
    parallel_bz2: bool = True

    @staticmethod
    def parse(path: Path, options: dict[str, Any]) -> CarmenOptions:
        known = set(CarmenOptions.__dataclass_fields__)
        unknown = sorted(set(options) - known)
        if unknown:
            names = option_names(sorted(known))
            raise DataError(
                f"{path}: unknown CARMEN loader option(s) {', '.join(unknown)}; "
                f"expected some of {', '.join(names)}{unknown_option_hint(unknown, names)}"
            )
        for key in ("max_range", "time_tolerance"):
            if options.get(key) is not None:
                try:
                    options[key] = float(options[key])
                except (TypeError, ValueError):
                    raise DataError(f"{path}: {key}={options[key]!r}; expected a number") from None
        options["max_pose_gap"] = max_pose_gap(options.get("max_pose_gap"), path)
        if "parallel_bz2" in options:
            options["parallel_bz2"] = _flag(path, "parallel_bz2", options["parallel_bz2"])
        opts = CarmenOptions(**options)
        if opts.odometry not in ODOMETRY_SOURCES:
            raise DataError(  # "reference" is taken by albot1.data.open before the loader runs
                f"{path}: odometry={opts.odometry!r}{did_you_mean(opts.odometry, [*ODOMETRY_SOURCES, 'reference'])}; "
                f"expected one of {', '.join(ODOMETRY_SOURCES)}, reference"
            )
        if opts.reference not in REFERENCE_SOURCES:
            raise DataError(f"{path}: reference={opts.reference!r}; expected one of {', '.join(REFERENCE_SOURCES)}")
        if opts.laser is not None and opts.laser not in LASER_MESSAGES:
            raise DataError(f"{path}: laser={opts.laser!r}; expected one of {', '.join(LASER_MESSAGES)}")
        if opts.max_range is not None and not (math.isfinite(opts.max_range) and opts.max_range > 0):
            raise DataError(f"{path}: max_range={opts.max_range!r}; expected a positive number of metres")
        if not opts.time_tolerance >= 0:  # inf disables the check (logs whose stamps are garbage)
            raise DataError(f"{path}: time_tolerance={opts.time_tolerance!r}; expected seconds >= 0 (or inf)")
        return opts


def _flag(path: Path, key: str, value: object) -> bool:
    """``true`` / ``false`` (any case, as a query writes them) or a bool; else a DataError naming the value.

    A query's ``parallel_bz2=false`` reached the loader as the text ``'false'``, which is true: the documented
    switch did nothing, and ``parallel_bz2=maybe`` was accepted.
    """
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.lower() in ("true", "false"):
        return value.lower() == "true"
    raise DataError(f"{path}: {key}={value!r}; expected true or false")


@dataclass(frozen=True)
class LoadOptions:
    """Everything :meth:`~albot1.data.loaders.carmen.loader.CarmenLoader.load` was given, sorted out."""

    carmen: CarmenOptions
    #: a relations file for the sequence (the catalog's, or ``FILE?relations=...``)
    relations: str | Path | None
    #: how its identically repeated lines count (``relations_repeats``; :mod:`albot1.data.relations`)
    relations_repeats: RepeatPolicy
    license: str
    citation: str


def parse_options(path: Path, options: dict[str, Any]) -> LoadOptions:
    """The catalog's fields and the validated CARMEN options of ``options`` (a DataError names a bad one)."""
    rest = dict(options)
    relations = rest.pop("relations", None)
    repeats = rest.pop("relations_repeats", None)
    if repeats is not None and relations is None:
        raise DataError(f"{path}: relations_repeats={repeats!r} goes with a relations file, and there is none")
    policy = "drop" if repeats is None else repeat_policy(repeats, str(path))
    license_text = str(rest.pop("license", ""))
    citation = str(rest.pop("citation", ""))
    return LoadOptions(CarmenOptions.parse(path, rest), relations, policy, license_text, citation)


def describe_odometry(mode: str, laser: str) -> str:
    """Which fields or lines the odometry source ``mode`` reads, for the metadata."""
    if mode == "laser-pose":
        fields = "odom_x odom_y odom_theta" if laser in OLD_LASERS else "robot_x robot_y robot_theta"
        return f"{laser} {fields} fields"
    if mode == "odom":
        return "ODOM lines, SE(2)-interpolated at the scan ipc timestamp"
    return "ODOM increments between scans, re-anchored at each corrected scan pose (GMapping log)"


def describe_reference(mode: str, laser: str) -> str:
    """Which fields or lines the (resolved) reference source ``mode`` reads, for the metadata; empty for none."""
    if mode == "none":
        return ""
    if mode == "truepos":
        return "TRUEPOS lines, SE(2)-interpolated at the scan ipc timestamp"
    fields = "x y theta" if laser in OLD_LASERS else "laser_x laser_y laser_theta"
    return f"{laser} {fields} fields (the laser's pose) composed with the inverse laser mount: the robot's pose"
