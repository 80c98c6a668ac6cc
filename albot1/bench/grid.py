"""The data that flows through the runner: cells, their outcomes and the grid plan.

Plain dataclasses that pickle (to Dask workers and child processes) and
round-trip through JSON (``grid.json``, ``cell.json``), so the report can be
rebuilt from the results folder alone.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Literal

Status = Literal["done", "cached", "failed"]
FailureKind = Literal["exception", "memory", "timeout", "crash", "config", "executor", "interrupted", "storage"]
#: The failures that are the method's own (its error, a crash, its limits), which a suite entry may allow
#: (``allow_failure``); a bad config, a lost executor, an interruption or a full disk never are.
METHOD_FAILURES: frozenset[FailureKind] = frozenset({"exception", "memory", "timeout", "crash"})


@dataclass(frozen=True)
class Cell:
    """One run of the grid: a dataset slice x method entry x degradation x seed, with its limits.

    ``key`` is the run folder name (:func:`albot1.runs.folder.run_key` of the
    dataset label, method, resolved config, degradation, seed, data and the
    ``versions`` its run will record), so a stored result is found again
    exactly when every input is the same. ``versions``: the part of the
    planned versions block the key digests (:func:`albot1.versions.key_versions`:
    code, libraries, programs, plugin), compared with what the cell's run
    records before it is stored (:func:`albot1.bench.cells.execute_cell`).
    """

    suite: str
    dataset: str
    dataset_label: str
    method: str
    method_label: str
    preset: str
    degradation: str
    seed: int
    key: str
    code_version: str
    time_s: float
    memory_mb: float
    limit: int | None = None
    stride: int | None = None
    overrides: dict[str, Any] = field(default_factory=dict)
    config: dict[str, Any] | None = None
    allow_failure: bool = False
    """The suite counts this cell's own failure as a finding (not in ``key``: it changes no result)."""
    trajectory: str | None = None
    """Another system's trajectory file, scored instead of running a method (:mod:`albot1.runs.external_run`)."""
    trajectory_format: str | None = None
    versions: dict[str, str | None] = field(default_factory=dict)

    def describe(self) -> str:
        """One line naming the cell for humans (progress, failure lists)."""
        return f"{self.method_label} on {self.dataset_label} [{self.degradation}, seed {self.seed}]"

    def to_json(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Cell:
        values = dict(data)
        # Written before suites named registered methods only (a cell could carry its own plugin target); such a
        # cell is planned again from its suite, which now refuses the target with one line.
        for legacy in ("target", "error_class", "requires"):
            if values.pop(legacy, None) not in (None, [], ()):
                raise TypeError(f"cell {values.get('key')!r} names a suite-defined {legacy}, which is no longer read")
        return cls(**values)


@dataclass(frozen=True)
class CellOutcome:
    """What became of one cell (returned by the job, shown by the progress view).

    ``halts_grid``: the failure is not the cell's own and would repeat for
    every cell (the results folder is full or read-only, the cell process
    pool was killed), so the runner starts no further cell.
    ``allowed``: a failure of the method itself (:data:`METHOD_FAILURES`) in
    a cell whose suite entry says ``allow_failure``; it is recorded and
    reported like any other but does not make the bench exit non-zero.
    ``kept``: an allowed failure recorded by an earlier run of this very cell
    (same key: same code version, config, data and seed) and not run again
    (:func:`albot1.bench.runner.kept_failure`).
    """

    key: str
    description: str
    method_label: str
    dataset_label: str
    status: Status
    elapsed_s: float = 0.0
    reason: str | None = None
    kind: FailureKind | None = None
    halts_grid: bool = False
    allowed: bool = False
    kept: bool = False

    @classmethod
    def of(
        cls,
        cell: Cell,
        status: Status,
        elapsed_s: float = 0.0,
        reason: str | None = None,
        kind: FailureKind | None = None,
        *,
        halts_grid: bool = False,
    ) -> CellOutcome:
        """The outcome of ``cell``, named by its key, description and labels."""
        return cls(
            cell.key,
            cell.describe(),
            cell.method_label,
            cell.dataset_label,
            status,
            elapsed_s,
            reason,
            kind,
            halts_grid,
            allowed=status == "failed" and cell.allow_failure and kind in METHOD_FAILURES,
        )


@dataclass(frozen=True)
class Skipped:
    """A dataset or method left out of the grid on this machine, and what to do about it."""

    name: str
    reason: str
    hint: str = ""


@dataclass
class GridPlan:
    """A suite expanded against this machine: the cells to run and what was left out."""

    suite: str
    suite_path: str | None
    description: str
    cells: list[Cell]
    skipped_datasets: list[Skipped]
    skipped_methods: list[Skipped]
    #: cells that cannot even start (their config does not resolve): key -> reason
    config_failures: dict[str, str]
    seeds: list[int]
    degradations: list[str]
    machine: dict[str, Any]

    def to_json(self) -> dict[str, Any]:
        return {
            "suite": self.suite,
            "suite_path": self.suite_path,
            "description": self.description,
            "cells": [c.to_json() for c in self.cells],
            "skipped_datasets": [asdict(s) for s in self.skipped_datasets],
            "skipped_methods": [asdict(s) for s in self.skipped_methods],
            "config_failures": self.config_failures,
            "seeds": self.seeds,
            "degradations": self.degradations,
            "machine": self.machine,
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> GridPlan:
        return cls(
            suite=data["suite"],
            suite_path=data.get("suite_path"),
            description=data.get("description", ""),
            cells=[Cell.from_json(c) for c in data["cells"]],
            skipped_datasets=[Skipped(**s) for s in data.get("skipped_datasets", [])],
            skipped_methods=[Skipped(**s) for s in data.get("skipped_methods", [])],
            config_failures=dict(data.get("config_failures", {})),
            seeds=list(data.get("seeds", [])),
            degradations=list(data.get("degradations", [])),
            machine=dict(data.get("machine", {})),
        )
