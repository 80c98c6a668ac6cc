"""The work of one cell, as it runs inside the cell's child process.

Open the dataset slice the cell names (its label, e.g. ``intel[:4000:2]``,
reopened by :func:`albot1.data.open.open_sequence`), run the method through
:func:`albot1.runs.execute.run_method` (which degrades the odometry with the
cell's seed), store the run folder and evaluate it, exactly as ``albot1 run``
+ ``albot1 evaluate`` do: the run folder keeps the dataset's relations and
the evaluation decides which of them the slice's scans can be scored on
(:func:`albot1.data.relations.relations_in_run`), counting the others. A run folder
that is complete but lacks ``metrics.json`` (the evaluation failed or was
killed last time) is only re-evaluated, not re-run.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, cast

from albot1 import versions
from albot1.bench.errors import BenchError, PlanMismatchError
from albot1.bench.grid import Cell
from albot1.config.targets import resolve_target
from albot1.data.model import Sequence
from albot1.data.open import open_sequence
from albot1.methods.registry import MethodRegistry
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.external_run import write_external_run
from albot1.runs.folder import PreviewRenderer, is_complete, write_run
from albot1.settings import Settings, get_settings

__all__ = [
    "check_versions",
    "config_difference",
    "execute_cell",
    "renderer_from_target",
    "renderer_target",
]


def renderer_target(renderer: PreviewRenderer) -> str:
    """``module:function`` naming ``renderer``: how a preview renderer reaches the cell processes.

    A cell runs in a child process started from JSON arguments (and possibly
    on a Dask worker), so the renderer travels by name and is imported there.
    """
    target = f"{renderer.__module__}:{renderer.__qualname__}"
    if resolve_target(target) is not renderer:
        raise BenchError(f"{target}: a preview renderer must be a module-level function importable by that name")
    return target


def renderer_from_target(target: str | None) -> PreviewRenderer | None:
    """The renderer named by :func:`renderer_target` (None: no previews)."""
    if target is None:
        return None
    renderer = resolve_target(target)
    if not callable(renderer):
        raise BenchError(f"{target}: expected a preview renderer function, found {type(renderer).__name__}")
    return cast(PreviewRenderer, renderer)


def config_difference(planned: dict[str, Any], ran: dict[str, Any]) -> str:
    """``field: planned A, ran B`` for each field that differs."""
    fields = sorted(set(planned) | set(ran))
    return "; ".join(
        f"{f}: planned {planned.get(f, '(absent)')!r}, ran {ran.get(f, '(absent)')!r}"
        for f in fields
        if planned.get(f) != ran.get(f)
    )


def check_versions(cell: Cell, ran: Mapping[str, str | None]) -> None:
    """PlanMismatchError naming each version that differs between the cell's plan and its run (``ran``: versions).

    The cell's key digests the versions planned (:attr:`Cell.versions`); a run with others (a library or MRPT
    upgraded while the grid ran, a Dask worker with another install) would be stored under a key naming versions
    it did not run with, so it is refused before it is stored, with what differs.
    """
    found = versions.key_versions(ran)
    if found != cell.versions:
        raise PlanMismatchError(
            f"{cell.describe()}: the versions in the cell process differ from the planned ones "
            f"({config_difference(cell.versions, found)}); was a library or MRPT installed while the grid was "
            "planned or running, or does this worker run another install? Install the same versions and run it again"
        )


def execute_cell(
    cell: Cell,
    runs_root: Path,
    settings: Settings | None = None,
    preview: PreviewRenderer | None = None,
    registry: MethodRegistry | None = None,
) -> Path:
    """Run, store and evaluate ``cell`` under ``runs_root/<key>``; returns the run folder.

    ``preview`` draws the run's ``preview.png`` (see :func:`albot1.runs.folder.write_run`);
    ``registry`` is the method registry (default: this process's, built once from the same installed
    entry points the planner read).
    """
    settings = settings or get_settings()
    run_dir = runs_root / cell.key
    if cell.trajectory is not None:  # another system's output: scored, not run (albot1.bench.external)
        check_versions(cell, versions.run_versions())
        written = write_external_run(
            path=Path(cell.trajectory),
            format_name=cell.trajectory_format,
            dataset=cell.dataset_label,
            method=cell.method,
            config=cell.config or {},
            seed=cell.seed,
            runs_root=runs_root,
            settings=settings,
            preview=preview,
        )
        if written.name != cell.key:
            raise PlanMismatchError(f"{cell.describe()}: stored under {written.name}, expected key {cell.key}")
        return written
    sequence: Sequence | None = (
        None  # opened only to run the cell; a run stored earlier is only evaluated (it reopens its data)
    )
    if not is_complete(run_dir):
        sequence = open_sequence(cell.dataset_label, settings=settings)
        result = run_method(
            cell.method,
            sequence,
            preset=cell.preset,
            overrides=dict(cell.overrides),
            degradation=cell.degradation,
            seed=cell.seed,
            dataset_name=cell.dataset_label,
            registry=registry,
        )
        if result.config != cell.config:
            raise PlanMismatchError(
                f"{cell.describe()}: the config resolved in the cell process differs from the "
                f"planned one ({config_difference(cell.config or {}, result.config)}); did a "
                "baselines/*.toml file or an ALBOT1_* variable change during the run?"
            )
        check_versions(cell, result.versions)
        written = write_run(result, runs_root, preview=preview)
        if written.name != cell.key:
            raise PlanMismatchError(
                f"{cell.describe()}: stored under {written.name}, expected key {cell.key} "
                "(the code or a data file changed while the grid was running?)"
            )
    evaluate_run(run_dir, settings=settings, opened=sequence)  # the log opened once a cell, not again for its metrics
    return run_dir
