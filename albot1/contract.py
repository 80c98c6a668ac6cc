"""What every mapper (Albot1 and each baseline) implements and returns.

A mapper is built from a typed (pydantic) config, is fed a Sequence frame by
frame through :meth:`Mapper.process` (the runner times exactly that call) and
hands back a :class:`MapperOutput` from :meth:`Mapper.finish`. Poses are
per scan, in the method's own map frame (any rigid offset from the reference
is removed by the metrics' alignment).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel

from albot1.data.model import Frame, Relations
from albot1.geometry.types import FloatArray
from albot1.records import Timing


@dataclass
class MapData:
    """A method's map: line surfaces (Albot1) and/or points (scan-projecting baselines).

    ``segments`` is ``(M, 4)`` as ``x1, y1, x2, y2``; ``segment_properties``
    (one JSON-able dict per segment: id, history, ...) is optional;
    ``points`` is ``(K, 2)``. Both are in the same frame as the poses.
    """

    segments: FloatArray | None = None
    points: FloatArray | None = None
    segment_properties: list[dict[str, Any]] | None = None

    def geometry_points(self, spacing: float = 0.05) -> FloatArray:
        """Points sampling the map (segments every ``spacing`` m plus points)."""
        parts: list[FloatArray] = []
        if self.segments is not None and len(self.segments):
            seg = np.asarray(self.segments, dtype=float)
            lengths = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
            counts = np.maximum(2, np.ceil(lengths / spacing).astype(int) + 1)
            parts.append(_sample_segments(seg, counts))
        if self.points is not None and len(self.points):
            parts.append(np.asarray(self.points, dtype=float))
        return np.concatenate(parts) if parts else np.empty((0, 2))


def _sample_segments(seg: FloatArray, counts: NDArray[np.int_]) -> FloatArray:
    """``counts[i]`` points along segment ``i``, in segment order: the bits of one ``np.linspace`` per segment.

    A loop of ``linspace`` calls cost ~10 us a segment (a default report samples ~160,000 segments); the same
    arithmetic on all of them at once: the k-th of n points is ``start + t * (end - start)`` with
    ``t = k * (1 / (n - 1))`` and the last ``t`` exactly 1, as ``linspace(0, 1, n)`` computes it.
    """
    owner = np.repeat(np.arange(len(seg)), counts)
    first = np.cumsum(counts) - counts
    k = np.arange(len(owner)) - first[owner]
    t = k * (1.0 / (counts - 1))[owner]
    t[first[1:] - 1] = 1.0
    if len(t):
        t[-1] = 1.0
    start, end = seg[owner, :2], seg[owner, 2:]
    return start + t[:, None] * (end - start)


@dataclass
class MapperOutput:
    """What :meth:`Mapper.finish` returns.

    ``counters`` must hold at least ``views`` (scans processed) and
    ``updates`` (map updates for Albot1; insertions/keyframes for baselines);
    ``extras`` holds JSON-able, method-specific records (update trace, ...);
    ``files`` extra files of the run folder by name (``places.json``, ...): a
    str is written as text, anything else as JSON (see
    :func:`albot1.runs.folder.write_run`); ``versions`` the version of each
    program outside Python the run ran, by name, as the program reported it
    in this run (MRPT's banner): recorded in ``result.json`` ``versions`` and
    part of the run's key, as the planner read it before the run
    (``Mapper.program_versions``).
    """

    poses: FloatArray
    map: MapData
    counters: dict[str, int | float]
    extras: dict[str, Any] = field(default_factory=dict)
    files: dict[str, Any] = field(default_factory=dict)
    versions: dict[str, str | None] = field(default_factory=dict)


@runtime_checkable
class Mapper(Protocol):
    """A mapping method. Classes also carry ``name``, ``config_model`` and ``presets``."""

    name: ClassVar[str]
    config_model: ClassVar[type[BaseModel]]
    #: preset name -> field overrides on top of the config model's defaults; has "default".
    presets: ClassVar[dict[str, dict[str, Any]]]

    def __init__(self, config: Any, *, seed: int = 0) -> None:
        """Build from a validated ``config_model`` instance; ``seed`` drives any random choice."""
        ...

    def process(self, frame: Frame) -> None:
        """Consume one frame (the only call that is timed per scan)."""
        ...

    def finish(self) -> MapperOutput:
        """Final poses (one per processed frame), map and counters."""
        ...

    # Optional, not part of the protocol's check: ``warm_up(self, announce: Callable[[str], None] | None) -> None``
    # does once what would otherwise land on the first timed scan (e.g. compiling kernels); the runner calls it
    # before the timed loop and records its time as ``startup_s``; ``announce`` takes a line for the user.
    # Optional too: ``preload_modules: ClassVar[tuple[str, ...]]``, the modules of its library the mapper imports
    # only when it is built; the bench's forkserver imports them once, before it forks any cell
    # (:mod:`albot1.bench.preload`), instead of each cell importing them again.
    # Optional too: ``program_versions(cls) -> dict[str, str | None]`` (a classmethod), the versions of the programs
    # outside Python the mapper runs (MRPT's applications), read before any run: the planner puts them in each
    # cell's key (:func:`albot1.versions.run_versions`), and a run reports the same names in ``MapperOutput.versions``.


@dataclass
class RunResult:
    """One method run on one (possibly degraded) sequence, ready to store.

    :func:`albot1.runs.folder.write_run` turns it into a run folder; its
    ``result.json`` is an :class:`albot1.records.ResultRecord`.
    """

    method: str
    dataset: str
    preset: str
    degradation: str
    seed: int
    config: dict[str, Any]
    timestamps: FloatArray
    poses: FloatArray
    odometry: FloatArray
    reference: FloatArray | None
    relations: Relations | None
    map: MapData
    counters: dict[str, int | float]
    extras: dict[str, Any]
    per_scan_ns: NDArray[np.int64]
    finish_s: float
    total_s: float
    wall_s: float
    peak_mb: float
    versions: dict[str, Any]
    dataset_info: dict[str, Any] = field(default_factory=dict)
    #: the mapper's extra files (``MapperOutput.files``), written beside the standard ones
    files: dict[str, Any] = field(default_factory=dict)
    #: CPU seconds over the span of ``wall_s`` (this process's threads + waited children); None when not measured
    cpu_s: float | None = None
    #: seconds of the mapper's ``warm_up`` before the first scan (0 for a mapper without one)
    startup_s: float = 0.0
    #: why the per-scan times are not the method's cost (a batch method working in ``finish``), else None
    per_scan_reason: str | None = None

    def timing(self) -> Timing:
        """The ``timing`` block of ``result.json``.

        Per-scan statistics are None for a run of no scans, and with ``per_scan_reason`` (the times are not the
        method's cost) beside them.
        """
        ms = self.per_scan_ns.astype(float) / 1e6
        timed = len(ms) > 0 and self.per_scan_reason is None
        return Timing(
            per_scan_ms_median=float(np.median(ms)) if timed else None,
            per_scan_ms_p95=float(np.percentile(ms, 95)) if timed else None,
            per_scan_ms_mean=float(np.mean(ms)) if timed else None,
            finish_s=self.finish_s,
            startup_s=self.startup_s,
            total_s=self.total_s,
            wall_s=self.wall_s,
            peak_mb=self.peak_mb,
            cpu_s=self.cpu_s,
            per_scan_reason=self.per_scan_reason,
        )
