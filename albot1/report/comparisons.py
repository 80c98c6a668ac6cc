"""Paired comparisons of methods on the report's pages: the errors each run folder yields, paired and compared.

A page that ranks methods ("A beats B") must show the evidence, and the
evidence must compare like with like: the errors of two runs on the same
data (dataset, degradation and seed) at the same scans or the same
ground-truth relations. This module reads those errors back from the run
folders and hands them to the project's one paired comparison
(:func:`albot1.metrics.paired.compare`), which gives a ratio, its bootstrap
interval and a verdict.

Two kinds of errors, one per table that needs them:

- **position** (m): the per-scan position error after the run's rigid SE(2)
  alignment to the reference poses, i.e. the errors whose RMSE is the run's
  ATE (compared as a ratio of RMSEs);
- **relation** translation (m) and rotation (deg): the per-relation errors of
  the relation metric (Kuemmerle et al. 2009), relations that the run's scans
  do not cover left out as the metric leaves them (compared as a ratio of
  means, the relation metric's own figure).

The errors are recomputed from the run folder, not stored: each is checked
against the run's own ``metrics.json`` (ATE RMSE, or relation mean and N),
and a run whose folder does not reproduce it (metrics written by another
version of the code) is not compared, with that reason. An external
trajectory's folder keeps the poses matched to scans, stamped with their
scans' stamps, which are the poses its metrics were scored on.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Final, Literal

import numpy as np
from numpy.typing import NDArray

from albot1.errors import Albot1Error
from albot1.metrics.ate import position_errors
from albot1.metrics.measures.ate import METRIC as ATE
from albot1.metrics.measures.relations import METRIC as RELATIONS
from albot1.metrics.paired import PERFECT_REFERENCE, UNBOUNDED, Comparison, compare, not_applicable
from albot1.metrics.relations import relation_errors
from albot1.report.collect import CellRecord

Kind = Literal["position", "relation translation", "relation rotation"]
#: how each kind of error is pooled: the power of the ratio (2: RMSE, 1: mean) and the figure it compares
POWER: Final[dict[Kind, int]] = {"position": 2, "relation translation": 1, "relation rotation": 1}
FIGURE: Final[dict[Kind, str]] = {
    "position": "ATE (ratio of RMSEs over the paired scans)",
    "relation translation": "relation metric, translation (ratio of mean errors over the paired relations)",
    "relation rotation": "relation metric, rotation (ratio of mean errors over the paired relations)",
}
#: relative tolerance of the check that the recomputed errors reproduce the run's metrics.json
REPRODUCE_RTOL: Final = 1e-6
NOT_REPRODUCED: Final = (
    "its run folder does not reproduce its metrics.json (the metrics were written by another version of the code, "
    "e.g. an external file's relations looked up at the file's own stamps: albot1 evaluate the run again)"
)


@dataclass(frozen=True)
class Errors:
    """One run's errors by key (scan index or relation line), or why it has none."""

    keys: NDArray[np.int64]
    values: dict[Kind, NDArray[np.float64]]
    missing: str | None = None


def _none(reason: str) -> Errors:
    return Errors(np.empty(0, dtype=np.int64), {}, reason)


def _close(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=REPRODUCE_RTOL, abs_tol=1e-12)


def position_errors_of(rec: CellRecord) -> Errors:
    """Per-scan position errors of ``rec``'s run (the errors of its ATE), keyed by scan index."""
    if rec.status != "done" or rec.metrics is None:
        return _none(f"no completed run ({rec.status})")
    block = rec.metrics.get(ATE)
    if block is None:
        return _none(rec.metrics.reason(ATE.name) or "no ATE")
    run = rec.stored_run()
    if run.reference is None or len(run.reference) != len(run.poses):
        return _none("no reference poses in its run folder")
    try:
        errors = position_errors(run.poses, run.reference, block.alignment)
    except Albot1Error as exc:
        return _none(str(exc))
    if not _close(float(np.sqrt(np.mean(errors**2))), block.rmse_m):
        return _none(NOT_REPRODUCED)
    return Errors(np.arange(len(errors), dtype=np.int64), {"position": errors})


def relation_errors_of(rec: CellRecord) -> Errors:
    """Per-relation translation (m) and rotation (deg) errors of ``rec``'s run, keyed by relation line."""
    if rec.status != "done" or rec.metrics is None:
        return _none(f"no completed run ({rec.status})")
    block = rec.metrics.get(RELATIONS)
    if block is None:
        return _none(rec.metrics.reason(RELATIONS.name) or "no relation metric")
    run = rec.stored_run()
    if run.relations is None or not len(run.timestamps):
        return _none("no relations in its run folder")
    try:
        errors, used = relation_errors(run.timestamps, run.poses, run.relations, outside="exclude")
    except Albot1Error as exc:
        return _none(str(exc))
    translation = np.hypot(errors[:, 0], errors[:, 1])
    recorded = block.translation_m.mean
    if len(translation) != block.translation_m.n or (
        len(translation) and (recorded is None or not _close(float(np.mean(translation)), recorded))
    ):
        return _none(NOT_REPRODUCED)
    return Errors(
        np.flatnonzero(used).astype(np.int64),
        {"relation translation": translation, "relation rotation": np.degrees(np.abs(errors[:, 2]))},
    )


def paired(a: Errors, b: Errors, kind: Kind) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A's and B's errors of ``kind`` at the keys both have, in key (route) order."""
    common, ia, ib = np.intersect1d(a.keys, b.keys, assume_unique=True, return_indices=True)
    del common
    return a.values[kind][ia], b.values[kind][ib]


def compare_runs(runs: Sequence[tuple[Errors, Errors]], kind: Kind, *, seed: int = 0) -> Comparison:
    """A against B over paired runs (one pair of runs per seed: the groups of the bootstrap), or why not."""
    missing = [e.missing for pair in runs for e in pair if e.missing is not None]
    usable = [(a, b) for a, b in runs if a.missing is None and b.missing is None]
    if not usable:
        return not_applicable(missing[0] if missing else "no run of both on the same data")
    return compare([paired(a, b, kind) for a, b in usable], power=POWER[kind], seed=seed)


def seeds_paired(
    mine: Iterable[CellRecord], theirs: Iterable[CellRecord], errors: dict[str, Errors]
) -> list[tuple[Errors, Errors]]:
    """The runs of two methods on the same data, paired by seed (``errors``: by cell key), in seed order."""
    by_seed = {r.cell.seed: r for r in theirs}
    return [
        (errors[r.cell.key], errors[by_seed[r.cell.seed].cell.key])
        for r in sorted(mine, key=lambda r: r.cell.seed)
        if r.cell.seed in by_seed
    ]


#: the reasons a comparison does not apply that are about B's errors alone (its mirror would misstate them)
ABOUT_B: Final = (PERFECT_REFERENCE, UNBOUNDED)

#: a matrix cell's two comparisons: relation translation, relation rotation (or a single kind twice over)
Cell = tuple[Comparison, ...]


def all_pairs(labels: Sequence[str], errors: dict[str, Errors], kinds: Sequence[Kind]) -> dict[tuple[str, str], Cell]:
    """Every ordered pair of ``labels`` compared on each of ``kinds`` (one run each); B-vs-A mirrors A-vs-B.

    Except where A-vs-B does not apply because of B's errors (B perfect, or zero on nearly every pair): that
    says nothing of B against A (a perfect method is *better*), so that direction is compared on its own.
    """
    found: dict[tuple[str, str], Cell] = {}
    for i, a in enumerate(labels):
        for b in labels[i + 1 :]:
            cell = tuple(compare_runs([(errors[a], errors[b])], kind) for kind in kinds)
            found[(a, b)] = cell
            found[(b, a)] = tuple(
                compare_runs([(errors[b], errors[a])], kind) if c.reason in ABOUT_B else c.mirrored()
                for c, kind in zip(cell, kinds, strict=True)
            )
    return found


def matrix_lines(
    labels: Sequence[str], found: dict[tuple[str, str], Cell], corner: str, shown: dict[str, str] | None = None
) -> list[str]:
    """A Markdown matrix: row method against column method, each cell its comparisons' ``short()`` joined by /.

    ``shown``: a label's heading where it differs from the label (a held-in method's mark, say).
    """
    name = shown or {}
    heads = [name.get(label, label) for label in labels]
    lines = ["| " + corner + " | " + " | ".join(heads) + " |", "|---|" + "---|" * len(labels)]
    for a in labels:
        cells = ["·" if a == b else " / ".join(c.short() for c in found[(a, b)]) for b in labels]
        lines.append(f"| {name.get(a, a)} | " + " | ".join(cells) + " |")
    return lines
