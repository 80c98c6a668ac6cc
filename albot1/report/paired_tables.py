"""The metrics tables' paired comparisons: each method against a reference method and against the best, over seeds.

The accuracy tables (``metrics.md``, ``index.html``) rank methods by a mean
over seeds; whether one method beats another there is a question about the
pairs of runs, not about two means. Per dataset and degradation, every
method's runs are paired with the reference method's runs of the same seed
(same dataset, degradation and seed: the same scans and the same noise) and
with those of the *best* method there (the lowest pooled error), and each
pair of runs contributes its paired errors (:mod:`albot1.report.comparisons`)
to one comparison (:func:`albot1.metrics.paired.compare`; the seeds are its
strata).

Which error: the per-scan position error (ATE, a ratio of RMSEs) on a dataset
whose runs have reference poses, else the relation metric's translation error
(a ratio of means) on one with ground-truth relations, else none (said so).
The reference is ``odometry`` when the suite ran it on that data (does the
method improve on doing nothing?), else the first method of the suite there.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from html import escape
from pathlib import Path

import numpy as np

from albot1.atomic import atomic_write
from albot1.metrics.measures.ate import METRIC as ATE
from albot1.metrics.measures.relations import METRIC as RELATIONS
from albot1.metrics.paired import CONFIDENCE, MIN_PAIRS, ZERO_ERROR, Comparison, method_text, not_applicable
from albot1.report.collect import CellRecord
from albot1.report.comparisons import (
    FIGURE,
    POWER,
    Errors,
    Kind,
    compare_runs,
    position_errors_of,
    relation_errors_of,
    seeds_paired,
)
from albot1.report.markdown import text as md_text
from albot1.report.tuning import LEGEND, combined, csv_flag, marked, record_held_in

TABLE = "paired.csv"
ODOMETRY = "odometry"
REFERENCE = "reference"
BEST = "best"
#: why a degradation has no best method: no method's errors could be read back (each run's reason is noted)
NO_ERRORS = "no method has errors that could be read back, so none is the best"
#: why the method with the lowest pooled error is not called the best: no other method's runs paired with its
NO_EVIDENCE = "lowest pooled error, but no run of another method could be compared with its runs"
#: why it is not called the best either when other methods' runs did pair with its, but none of those comparisons
#: applies (fewer pairs than the test needs, say); the first of their reasons follows in parentheses
NO_DECISION = "lowest pooled error, but no other method's comparison with its runs applies"


@dataclass(frozen=True)
class PairedRow:
    """One method on one dataset and degradation, against the reference method and against the best."""

    dataset: str
    degradation: str
    method: str
    kind: Kind
    runs: int
    reference: str
    #: None: no method has errors to rank (every ``against_best`` is then n/a with the reason)
    best: str | None
    #: None: this method is the reference / the best (the best only when a comparison against it applies)
    against_reference: Comparison | None
    against_best: Comparison | None
    #: why the method's runs give no errors to compare (every comparison of the row is then n/a)
    missing: str | None = None
    #: each method of the group -> whether its runs here are held-in (:func:`albot1.report.tuning.combined`;
    #: None: its tuning is unknown), so a claim "A beats B" says when A or B was tuned on this data
    held_in: dict[str, bool | None] = field(default_factory=dict)

    def held(self, method: str | None) -> bool | None:
        """Whether ``method``'s runs in this comparison are held-in (None: unknown or no such method)."""
        return None if method is None else self.held_in.get(method)


def error_kind(records: list[CellRecord]) -> Kind | None:
    """ATE errors when a completed run of these has an ATE, else relation errors when one has relations."""
    done = [r.metrics for r in records if r.status == "done" and r.metrics is not None]
    if any(m.block(ATE.name) is not None for m in done):
        return "position"
    if any(m.block(RELATIONS.name) is not None for m in done):
        return "relation translation"
    return None


def _pooled(errors: list[Errors], kind: Kind) -> float:
    values = [e.values[kind] for e in errors if e.missing is None]
    if not values or not sum(len(v) for v in values):
        return math.inf
    flat = np.concatenate(values)
    return float(np.sqrt(np.mean(flat**2))) if POWER[kind] == 2 else float(np.mean(flat))


def paired_rows(records: list[CellRecord]) -> list[PairedRow]:
    """A :class:`PairedRow` per method of every (dataset, degradation) with at least two methods that completed."""
    groups: dict[tuple[str, str], list[CellRecord]] = {}
    for rec in records:
        if rec.status == "done":
            groups.setdefault((rec.cell.dataset_label, rec.cell.degradation), []).append(rec)
    kinds = {
        dataset: error_kind([r for r in records if r.cell.dataset_label == dataset])
        for dataset in dict.fromkeys(r.cell.dataset_label for r in records)
    }
    out: list[PairedRow] = []
    for (dataset, degradation), recs in groups.items():
        kind = kinds[dataset]
        by_method: dict[str, list[CellRecord]] = {}
        for rec in recs:
            by_method.setdefault(rec.cell.method_label, []).append(rec)
        if kind is not None and len(by_method) >= 2:
            out += _group_rows(dataset, degradation, kind, by_method)
    return out


def _group_rows(dataset: str, degradation: str, kind: Kind, by_method: dict[str, list[CellRecord]]) -> list[PairedRow]:
    """The rows of one dataset and degradation: every method against the reference and the best there."""
    read = position_errors_of if kind == "position" else relation_errors_of
    errors = {rec.cell.key: read(rec) for recs in by_method.values() for rec in recs}
    pooled = {m: _pooled([errors[r.cell.key] for r in rs], kind) for m, rs in by_method.items()}
    reference = ODOMETRY if ODOMETRY in by_method else next(iter(by_method))
    # the first of equals, in suite order, of the methods with errors (an infinite pooled error: none could be read
    # back); a perfect method (the reference poses given as odometry) is no yardstick
    ranked = [m for m in by_method if math.isfinite(pooled[m])]
    rated = [m for m in ranked if pooled[m] >= ZERO_ERROR] or ranked
    best = min(rated, key=lambda m: pooled[m]) if rated else None
    against_best = {
        method: not_applicable(NO_ERRORS)
        if best is None
        else None
        if method == best
        else compare_runs(seeds_paired(mine, by_method[best], errors), kind)
        for method, mine in by_method.items()
    }
    if best is not None and not any(found is not None and found.applies for found in against_best.values()):
        against_best[best] = _unproven_best(list(against_best.values()))
    held = {method: combined(record_held_in(r) for r in mine) for method, mine in by_method.items()}
    rows = []
    for method, mine in by_method.items():
        missing = next((errors[r.cell.key].missing for r in mine if errors[r.cell.key].missing), None)
        rows.append(
            PairedRow(
                dataset,
                degradation,
                method,
                kind,
                len(mine),
                reference,
                best,
                None if method == reference else compare_runs(seeds_paired(mine, by_method[reference], errors), kind),
                against_best[method],
                missing,
                held,
            )
        )
    return rows


def _unproven_best(comparisons: list[Comparison | None]) -> Comparison:
    """The best's own n/a when no comparison against it applies: never paired, or paired without a verdict.

    Saying "could not be compared" of runs that were paired (3 scans each: "3 pairs, fewer than 10") would
    give a false reason, so the reason names what the paired comparisons said.
    """
    paired = [found for found in comparisons if found is not None and found.pairs > 0]
    if not paired:
        return not_applicable(NO_EVIDENCE)
    return not_applicable(f"{NO_DECISION} ({paired[0].reason})")


def _cell(found: Comparison | None, role: str) -> str:
    """``better 0.42 [0.38–0.47]``, ``n/a`` (the reason under the table), or the row's role."""
    if found is None:
        return role
    return f"{found.verdict} {found.text()}" if found.applies else "n/a"


def _against(row: PairedRow, other: str | None, quote: Callable[[str], str] = str) -> str:
    """`` (other)``: the method a cell compares with, held-in marked; nothing for the row's own role or none."""
    return "" if other is None or other == row.method else f" ({quote(marked(other, row.held(other)))})"


def _any_held_in(rows: list[PairedRow]) -> bool:
    """Whether a comparison of ``rows`` involves a held-in side (then the table states the mark's legend)."""
    return any(v is True for r in rows for v in r.held_in.values())


def _notes(rows: list[PairedRow]) -> list[str]:
    """Why comparisons are n/a or runs left out, each reason once with the comparisons it applies to."""
    why: dict[str, list[str]] = {}
    for r in rows:
        for other, found in ((r.reference, r.against_reference), (r.best, r.against_best)):
            if found is not None and not found.applies:
                where = f"{r.method} as the best" if other == r.method else f"{r.method} against {other or BEST}"
                why.setdefault(f"n/a: {found.reason}", []).append(f"{where} ({r.degradation})")
        if r.missing is not None:
            why.setdefault(f"a run not compared: {r.missing}", []).append(f"{r.method} ({r.degradation})")
    return [f"{reason}: {'; '.join(dict.fromkeys(where))}" for reason, where in why.items()]


def _counts(row: PairedRow) -> str:
    found = row.against_reference or row.against_best
    if found is None or not found.pairs:
        return "–"
    return f"{found.pairs} ({found.groups})"


def intro() -> str:
    """What every paired table of the metrics pages means (stated once, above the tables)."""
    return (
        "**Paired comparisons** (under each dataset's table): each method against the reference method (odometry "
        "where the suite ran it, else the suite's first method there) and against the best method of the same "
        "degradation (lowest pooled error, a perfect one aside), on runs of the same dataset, degradation and "
        "seed (the same scans or relations), seeds pooled as strata; the number is the ratio of the method's "
        "error to the other's "
        f"(< 1: lower) with its {CONFIDENCE:.0%} interval; test: {method_text()}. *pairs (runs)*: the errors "
        f"paired and the pairs of runs they come from. Fewer than {MIN_PAIRS} pairs, or a run whose errors cannot "
        "be read back, is n/a with the reason; so is the best's own cell when no other method's comparison with "
        "its runs applies. A claim that one method beats another holds only where its row says better or worse; "
        "a method marked held-in (the mark after its name, either side) was tuned on that data, so the claim "
        "shows fit there, not generalisation."
    )


def no_pairs() -> str:
    """What the metrics page says when it has no paired table at all (a store of one method, say), so an empty
    ``paired.csv`` is not taken for a comparison that found nothing."""
    return (
        "**Paired comparisons**: none. No dataset and degradation here has two methods whose completed runs "
        "report errors that can be paired (position errors against reference poses, or relation errors), so "
        "`paired.csv` holds only its header."
    )


def markdown_lines(rows: list[PairedRow], dataset: str) -> list[str]:
    """The paired table of one dataset (no lines when it has none)."""
    mine = [r for r in rows if r.dataset == dataset]
    if not mine:
        return []
    lines = [
        f"Paired comparison, {md_text(FIGURE[mine[0].kind])}:",
        "",
        "| method | degradation | pairs (runs) | against the reference | against the best |",
        "|---|---|---:|---|---|",
    ]
    for r in mine:
        ref = _cell(r.against_reference, REFERENCE)
        best = _cell(r.against_best, BEST)
        lines.append(
            f"| {md_text(marked(r.method, r.held(r.method)))} | {md_text(r.degradation)} | {_counts(r)} | "
            f"{ref}{_against(r, r.reference, md_text)} | {best}{_against(r, r.best, md_text)} |"
        )
    notes = [f"- {md_text(note)}" for note in _notes(mine)] + ([f"- {LEGEND}"] if _any_held_in(mine) else [])
    return [*lines, "", *notes, *([""] if notes else [])]


def html_table(rows: list[PairedRow], dataset: str) -> str:
    """The same table for ``index.html`` (empty when the dataset has none)."""
    mine = [r for r in rows if r.dataset == dataset]
    if not mine:
        return ""
    head = "".join(
        f"<th>{h}</th>" for h in ("method", "degradation", "pairs (runs)", "against the reference", "against the best")
    )
    body = []
    for r in mine:
        ref = _cell(r.against_reference, REFERENCE) + _against(r, r.reference)
        best = _cell(r.against_best, BEST) + _against(r, r.best)
        body.append(
            f"<tr><td>{escape(marked(r.method, r.held(r.method)))}</td><td>{escape(r.degradation)}</td>"
            f"<td>{escape(_counts(r))}</td>"
            f"<td>{escape(ref)}</td><td>{escape(best)}</td></tr>"
        )
    notes = "".join(f"<li>{escape(note)}</li>" for note in _notes(mine))
    notes += f"<li>{escape(LEGEND)}</li>" if _any_held_in(mine) else ""
    return (
        f'<p class="notes">Paired comparison, {escape(FIGURE[mine[0].kind])}: {escape(method_text())}.</p>'
        f'<div class="scroll"><table class="sortable"><thead><tr>{head}</tr></thead><tbody>'
        + "".join(body)
        + "</tbody></table></div>"
        + (f'<ul class="notes">{notes}</ul>' if notes else "")
    )


def write_paired_csv(rows: list[PairedRow], out: Path) -> Path:
    """``paired.csv``: one line per comparison (method against the reference, against the best).

    ``held_in`` / ``against_held_in``: whether the method's / the other method's runs there are held-in (its
    values were tuned on that data), empty when unknown; on the best's own line (no other method) the latter
    is empty.
    """
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(
        ["dataset", "degradation", "method", "against", "role", "error", "pairs", "runs", "ratio", "low", "high"]
        + ["verdict", "reason", "held_in", "against_held_in"]
    )
    for r in rows:
        for role, other, found in ((REFERENCE, r.reference, r.against_reference), (BEST, r.best, r.against_best)):
            if found is None:
                continue
            numbers = ["" if math.isnan(v) else f"{v:.9g}" for v in (found.ratio, found.low, found.high)]
            writer.writerow(
                [r.dataset, r.degradation, r.method, "" if other in (None, r.method) else other, role, r.kind]
                + [found.pairs, found.groups, *numbers]
                + [found.verdict, found.reason or "", csv_flag(r.held(r.method))]
                + ["" if other in (None, r.method) else csv_flag(r.held(other))]
            )
    path = out / TABLE
    text = buffer.getvalue()
    atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return path
