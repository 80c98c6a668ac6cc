"""The standard-benchmark page's paired comparisons: every two measured methods of a log on the same relations.

Kept apart from :mod:`albot1.report.standard` (the page and its rows) so that each stays a module one can
read whole; the page calls :func:`compare_by_log` with its own rule of which cell is a whole-log run.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable
from dataclasses import dataclass, field

from albot1.report.collect import CellRecord
from albot1.report.comparisons import Cell, Errors, all_pairs, matrix_lines, relation_errors_of
from albot1.report.tuning import csv_flag, marked, record_held_in

PAIRED_TABLE = "standard-benchmark-paired.csv"


@dataclass(frozen=True)
class Paired:
    """One log's paired comparisons: every two measured methods on the same relations (translation, rotation)."""

    labels: list[str]
    found: dict[tuple[str, str], Cell]
    #: method -> why its run is not compared (its relation errors cannot be read back)
    left_out: dict[str, str]
    #: method -> the seed of its compared run, kept only when some method of the log ran several seeds
    seeds: dict[str, int] = field(default_factory=dict)
    #: method -> whether its compared run is held-in (:func:`albot1.report.tuning.record_held_in`; None: unknown)
    held_in: dict[str, bool | None] = field(default_factory=dict)


def shown_record(group: list[CellRecord]) -> CellRecord:
    """The record the page shows of one (log, method)'s seeds: the lowest completed seed, else the lowest seed.

    One rule for the row and its paired comparisons, whatever order the store lists the seeds in: a failed seed
    never hides a completed one, and the matrix compares the very runs the rows show.
    """
    done = [rec for rec in group if rec.status == "done"]
    return min(done or group, key=lambda rec: rec.cell.seed)


def compare_by_log(records: list[CellRecord], whole_log: Callable[[CellRecord], bool]) -> dict[str, Paired]:
    """Per log, each method's shown ``whole_log`` cell (:func:`shown_record`), compared pairwise on like relations."""
    groups: dict[str, dict[str, list[CellRecord]]] = {}
    for rec in records:
        if whole_log(rec):
            groups.setdefault(rec.cell.dataset_label, {}).setdefault(rec.cell.method_label, []).append(rec)
    first = {log: {m: shown_record(g) for m, g in by.items()} for log, by in groups.items()}
    out: dict[str, Paired] = {}
    for log, by_method in first.items():
        errors: dict[str, Errors] = {m: relation_errors_of(r) for m, r in by_method.items() if r.status == "done"}
        labels = [m for m, e in errors.items() if e.missing is None]
        left_out = {m: str(e.missing) for m, e in errors.items() if e.missing is not None}
        found = all_pairs(labels, errors, ("relation translation", "relation rotation"))
        several = any(len(group) > 1 for group in groups[log].values())
        seeds = {m: by_method[m].cell.seed for m in labels} if several else {}
        held = {m: record_held_in(by_method[m]) for m in labels}
        out[log] = Paired(labels, found, left_out, seeds, held)
    return out


def paired_lines(paired: Paired | None) -> list[str]:
    """The page's lines under one log: the matrix, the methods left out and each n/a reason once."""
    if paired is None or len(paired.labels) + len(paired.left_out) < 2:
        return []
    lines = ["Paired comparison (row against column, the same relations; translation / rotation):", ""]
    if len(paired.labels) >= 2:
        shown = {m: marked(m, paired.held_in.get(m)) for m in paired.labels}
        lines += [*matrix_lines(paired.labels, paired.found, "row vs column", shown), ""]
    lines += [f"- {m}: not compared: {why}" for m, why in paired.left_out.items()]
    lines += _seeds_lines(paired.seeds)
    why: dict[str, list[str]] = {}  # each n/a reason once, with the comparisons it applies to
    for i, a in enumerate(paired.labels):
        for b in paired.labels[i + 1 :]:
            for kind, found in zip(("translation", "rotation"), paired.found[(a, b)], strict=True):
                if not found.applies:
                    why.setdefault(str(found.reason), []).append(f"{a} vs {b} ({kind})")
    lines += [f"- `–` {reason}: {'; '.join(where)}" for reason, where in why.items()]
    return [*lines, ""] if paired.left_out or why or paired.seeds else lines


def _seeds_lines(seeds: dict[str, int]) -> list[str]:
    """Which seed each compared run is (the row's), said when a method ran several; a mix of seeds said as such."""
    if not seeds:
        return []
    runs = ", ".join(f"{m} seed {seed}" for m, seed in seeds.items())
    mixed = (
        ": not the same seed for every method (a failed seed is replaced by the method's lowest completed one), "
        "so a ratio also compares the methods' randomness"
        if len(set(seeds.values())) > 1
        else ""
    )
    return [f"- runs compared: {runs}{mixed}"]


def paired_csv(paired: dict[str, Paired]) -> str:
    """Each unordered pair of measured methods per log once (row before column in the page's order).

    ``held_in`` / ``against_held_in``: whether the method's / the other's run was tuned on the log (empty:
    unknown), so a row "A beats B" says when either side's values were chosen there.
    """
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    header = ["log", "method", "against", "error", "relations", "ratio", "low", "high", "verdict", "reason"]
    writer.writerow([*header, "held_in", "against_held_in"])
    for log, entry in paired.items():
        for i, a in enumerate(entry.labels):
            for b in entry.labels[i + 1 :]:
                for kind, c in zip(("translation", "rotation"), entry.found[(a, b)], strict=True):
                    numbers = ["" if math.isnan(v) else f"{v:.9g}" for v in (c.ratio, c.low, c.high)]
                    held = [csv_flag(entry.held_in.get(m)) for m in (a, b)]
                    writer.writerow([log, a, b, kind, c.pairs, *numbers, c.verdict, c.reason or "", *held])
    return buffer.getvalue()
