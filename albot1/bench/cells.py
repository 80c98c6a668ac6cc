"""The work of one cell, as it runs inside the cell's child process.

Open the dataset, take the suite's slice (prefix and stride), run the method
through :func:`albot1.runs.execute.run_method` (which degrades the odometry
with the cell's seed), store the run folder and evaluate it. A run folder
that is complete but lacks ``metrics.json`` (the evaluation failed or was
killed last time) is only re-evaluated, not re-run.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from albot1.bench.errors import BenchError
from albot1.bench.grid import Cell
from albot1.data.model import Relations, Sequence
from albot1.runs.folder import is_complete
from albot1.settings import Settings, get_settings

#: a relation end counts as inside the slice when a kept scan is this close in time (s)
RELATION_TOLERANCE_S = 1e-3


def open_cell_sequence(cell: Cell, settings: Settings) -> Sequence:
    """The dataset slice of ``cell`` (its label, e.g. ``intel[:4000:2]``, is what ``open_sequence`` reopens).

    The relations of a slice are restricted to the kept scans, so the
    relation metric scores exactly the scans the method saw.
    """
    from albot1.data.open import open_sequence

    sequence = open_sequence(cell.dataset_label, settings=settings)
    if (cell.limit is None and cell.stride is None) or sequence.relations is None:
        return sequence
    return Sequence(
        sequence.name, sequence.frames, sequence.metadata, restrict_relations(sequence.relations, sequence.timestamps)
    )


def restrict_relations(relations: Relations, timestamps: np.ndarray) -> Relations | None:
    """The relations whose two ends are both kept scans (a slice must not be scored on scans it lacks)."""
    if len(timestamps) == 0:
        return None
    stamps = np.sort(np.asarray(timestamps, dtype=float))

    def kept(t: np.ndarray) -> np.ndarray:
        idx = np.clip(np.searchsorted(stamps, t), 1, len(stamps) - 1) if len(stamps) > 1 else np.zeros(len(t), int)
        nearest = np.minimum(np.abs(stamps[idx] - t), np.abs(stamps[np.maximum(idx - 1, 0)] - t))
        return nearest <= RELATION_TOLERANCE_S

    mask = kept(relations.t1) & kept(relations.t2)
    if not mask.any():
        return None
    return Relations(t1=relations.t1[mask], t2=relations.t2[mask], poses=relations.poses[mask])


def config_difference(planned: dict[str, Any], ran: dict[str, Any]) -> str:
    """``field: planned A, ran B`` for each field that differs."""
    fields = sorted(set(planned) | set(ran))
    return "; ".join(
        f"{f}: planned {planned.get(f, '(absent)')!r}, ran {ran.get(f, '(absent)')!r}"
        for f in fields
        if planned.get(f) != ran.get(f)
    )


def execute_cell(cell: Cell, runs_root: Path, settings: Settings | None = None) -> Path:
    """Run, store and evaluate ``cell`` under ``runs_root/<key>``; returns the run folder."""
    from albot1.runs.evaluate import evaluate_run
    from albot1.runs.execute import run_method
    from albot1.runs.folder import write_run

    if cell.target is not None:
        from albot1.bench.plan import register_plugin

        register_plugin(cell.method, cell.target, cell.error_class, cell.requires)
    settings = settings or get_settings()
    run_dir = runs_root / cell.key
    if not is_complete(run_dir):
        sequence = open_cell_sequence(cell, settings)
        result = run_method(
            cell.method,
            sequence,
            preset=cell.preset,
            overrides=dict(cell.overrides),
            degradation=cell.degradation,
            seed=cell.seed,
            dataset_name=cell.dataset_label,
        )
        if result.config != cell.config:
            raise BenchError(
                f"{cell.describe()}: the config resolved in the cell process differs from the "
                f"planned one ({config_difference(cell.config or {}, result.config)}); did a "
                "baselines/*.toml file or an ALBOT1_* variable change during the run?"
            )
        written = write_run(result, runs_root)
        if written.name != cell.key:
            raise BenchError(
                f"{cell.describe()}: stored under {written.name}, expected key {cell.key} "
                "(the code changed while the grid was running?)"
            )
    evaluate_run(run_dir, settings=settings)
    return run_dir
