"""Every method against the odometry it was given: the generalisation page, with a paired comparison per cell.

A mapper that is worse than its own odometry has made the robot's estimate
worse than doing nothing; on held-out logs (no preset file lists them as
tuned on) that is how a method that was fitted to its benchmark shows itself.
This page compares, for each (dataset, method, degradation) over its seeds,
the method's trajectory with the odometry *the same run was given* (the run
folder stores both, after the degradation, and the reference poses), so the
pair is exact: the same scans, the same noise.

ATE ratio: ``sqrt(sum e_m^2 / sum e_o^2)`` over every scan of every seed,
where ``e_m`` and ``e_o`` are the per-scan position errors of the method and
of its odometry, each after its own rigid SE(2) alignment to the reference
(:func:`albot1.metrics.ate.position_errors`), i.e. the ratio of the two
ATE RMSEs pooled over the seeds. Its confidence interval and verdict are
the project's one paired comparison (:mod:`albot1.metrics.paired`): a paired
moving-block bootstrap over scans (blocks of 1/20 of a run, resampled within
each seed, the same indices for both errors; the alignment is kept fixed)
from a fixed seed, so the page is reproducible. A cell is **worse** when the
whole interval is above 1, **better** when it is below 1, else
**indistinguishable** at :data:`~albot1.metrics.paired.CONFIDENCE`; where that
comparison does not apply (fewer than :data:`~albot1.metrics.paired.MIN_PAIRS`
scans, an unbounded interval) the cell says ``n/a`` and why, and a ratio to
perfect odometry is never formed (``perfect odometry``). RPE@10 m and
the loop gap are shown beside the odometry method's own cell of the same
dataset, degradation and seed (when the suite ran it): both as means over
the seeds where both have the number, so the ratio beside them compares the
same seeds (a seed whose odometry cell failed used to stay in the method's
mean and out of the odometry's); without an odometry number on any seed,
the method's mean over its own seeds and ``n/a``.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass, fields, replace
from pathlib import Path
from statistics import median
from typing import Any

import numpy as np

from albot1.atomic import atomic_write
from albot1.bench.grid import GridPlan
from albot1.metrics.ate import position_errors
from albot1.metrics.measures.ate import METRIC as ATE
from albot1.metrics.paired import (
    BLOCKS,
    CONFIDENCE,
    DIGITS,
    NOT_APPLICABLE,
    RATIO_TIE,
    RESAMPLES,
    ZERO_ERROR,
    compare,
    ratio_digits,
    ratio_text,
)
from albot1.report.collect import METRIC_COLUMNS, CellRecord
from albot1.report.markdown import text as md_text
from albot1.report.provenance import regenerate_command
from albot1.report.tuning import LEGEND, MARK, marked, record_held_in

PAGE = "generalisation.md"
TABLE = "generalisation.csv"
ODOMETRY = "odometry"
NA = "n/a"
#: An odometry ATE below this (m) is perfect odometry (the reference itself): a ratio to it means nothing, the
#: method's own ATE is the figure (issue 21's target for gtsam-graph: <= 0.3 m).
PERFECT_M = ZERO_ERROR
PERFECT = "perfect odometry"


@dataclass(frozen=True)
class Comparison:
    """One (dataset, method, degradation) against its odometry, over its completed seeds."""

    dataset: str
    method: str
    degradation: str
    seeds: int
    failed: int
    ate_m: float
    odometry_ate_m: float
    ratio: float
    ratio_low: float
    ratio_high: float
    verdict: str  # better | worse | indistinguishable | perfect odometry | n/a
    rpe10_m: float | None
    odometry_rpe10_m: float | None
    loop_gap_m: float | None
    odometry_loop_gap_m: float | None
    held_in: bool | None
    #: why the paired comparison does not apply (verdict n/a), else None
    reason: str | None = None


def paired_errors(rec: CellRecord) -> tuple[np.ndarray, np.ndarray] | None:
    """Per-scan position errors of the run's poses and of the odometry it was given, or None (no reference)."""
    if rec.status != "done" or rec.metrics is None or rec.metrics.get(ATE) is None:
        return None
    run = rec.stored_run()
    if run.reference is None:
        return None
    ok = np.isfinite(run.reference).all(axis=1)
    if ok.sum() < 2:
        return None
    return (
        position_errors(run.poses[ok], run.reference[ok]),
        position_errors(run.odometry[ok], run.reference[ok]),
    )


def _mean(values: list[float | None]) -> float | None:
    present = [v for v in values if v is not None]
    return sum(present) / len(present) if present else None


def _paired_means(mine: list[float | None], theirs: list[float | None]) -> tuple[float | None, float | None]:
    """The method's and the odometry's means over the seeds where both have a number (``mine[k]`` and
    ``theirs[k]``: seed k), so that their ratio compares the same seeds; where no seed has both, the method's
    mean over its own seeds and None."""
    both = [(m, o) for m, o in zip(mine, theirs, strict=True) if m is not None and o is not None]
    if not both:
        return _mean(mine), None
    return _mean([m for m, _ in both]), _mean([o for _, o in both])


def comparisons(records: list[CellRecord]) -> list[Comparison]:
    """A :class:`Comparison` per (dataset, method, degradation) with at least one scored run, in plan order."""
    rpe, gap = METRIC_COLUMNS["drift_10m_m"], METRIC_COLUMNS["loop_gap_m"]
    odometry_cells = {
        (r.cell.dataset_label, r.cell.degradation, r.cell.seed): r
        for r in records
        if r.cell.method == ODOMETRY and r.status == "done"
    }
    groups: dict[tuple[str, str, str], list[CellRecord]] = {}
    for rec in records:
        if rec.cell.method != ODOMETRY:
            groups.setdefault((rec.cell.dataset_label, rec.cell.method_label, rec.cell.degradation), []).append(rec)
    out: list[Comparison] = []
    for (dataset, method, degradation), recs in groups.items():
        scored = [(rec, errors) for rec in recs if (errors := paired_errors(rec)) is not None]
        if not scored:
            continue
        pairs = [errors for _, errors in scored]
        odometry_ate = math.sqrt(sum(float(np.sum(o**2)) for _, o in pairs) / sum(len(o) for _, o in pairs))
        # perfect odometry first: its table shows the method's ATE whatever the number of scans
        paired = compare(pairs) if odometry_ate >= PERFECT_M else None
        odo = [odometry_cells.get((dataset, degradation, rec.cell.seed)) for rec, _ in scored]
        rpe10 = _paired_means([rpe.value(rec) for rec, _ in scored], [None if o is None else rpe.value(o) for o in odo])
        loop_gap = _paired_means(
            [gap.value(rec) for rec, _ in scored], [None if o is None else gap.value(o) for o in odo]
        )
        out.append(
            Comparison(
                dataset=dataset,
                method=method,
                degradation=degradation,
                seeds=len(scored),
                failed=sum(rec.status == "failed" for rec in recs),
                ate_m=math.sqrt(sum(float(np.sum(m**2)) for m, _ in pairs) / sum(len(m) for m, _ in pairs)),
                odometry_ate_m=odometry_ate,
                ratio=math.nan if paired is None else paired.ratio,
                ratio_low=math.nan if paired is None else paired.low,
                ratio_high=math.nan if paired is None else paired.high,
                verdict=PERFECT if paired is None else paired.verdict,
                rpe10_m=rpe10[0],
                odometry_rpe10_m=rpe10[1],
                loop_gap_m=loop_gap[0],
                odometry_loop_gap_m=loop_gap[1],
                held_in=record_held_in(scored[0][0]),
                reason=None if paired is None else paired.reason,
            )
        )
    return out


def _listing(lead: str, items: list[str]) -> list[str]:
    """A paragraph ``lead: a; b; c.`` after a blank line, or nothing when ``items`` is empty."""
    return ["", f"{lead}: " + "; ".join(items) + "."] if items else []


def _num(value: float | None, digits: int = 3) -> str:
    return NA if value is None or not math.isfinite(value) else f"{value:.{digits}f}"


def _ratio(value: float, digits: int = DIGITS) -> str:
    return NA if not math.isfinite(value) else ratio_text(value, digits)


def _interval(row: Comparison) -> str:
    if row.verdict in (PERFECT, NOT_APPLICABLE):
        return NA
    digits = ratio_digits(row.ratio_low, row.ratio_high)  # enough to show the interval's side of 1
    return f"{_ratio(row.ratio, digits)} [{_ratio(row.ratio_low, digits)}–{_ratio(row.ratio_high, digits)}]"


def _verdict(row: Comparison) -> str:
    return f"{NA} ({row.reason})" if row.verdict == NOT_APPLICABLE else row.verdict


def _seeds(row: Comparison) -> str:
    return str(row.seeds) + (f" ({row.failed} failed)" if row.failed else "")


def _pair(value: float | None, odometry: float | None) -> str:
    if value is None:
        return NA
    if odometry is None or odometry < PERFECT_M:
        return f"{_num(value)} / {_num(odometry)}"
    return f"{_num(value)} / {_num(odometry)} ({value / odometry:.2f}x)"


def failed_groups(records: list[CellRecord]) -> list[str]:
    """``method on dataset (degradation)`` for every group of the page's kind without one completed run."""
    groups: dict[tuple[str, str, str], list[str]] = {}
    for rec in records:
        if rec.cell.method != ODOMETRY:
            key = (rec.cell.method_label, rec.cell.dataset_label, rec.cell.degradation)
            groups.setdefault(key, []).append(rec.status)
    return [f"{m} on {d} ({g})" for (m, d, g), statuses in groups.items() if "done" not in statuses]


def render_page(
    plan: GridPlan, rows: list[Comparison], failed: list[str] | None = None, *, regenerate: str | None = None
) -> str:
    """The Markdown page (see the module docstring); ``regenerate``: the commands that write it again
    (:func:`albot1.report.provenance.regenerate_command`; None: those of the default folders).

    Names and reasons come from suite files and runs: they are written as text (:mod:`albot1.report.markdown`),
    so a ``|`` in a method's name no longer splits its row and ``<b>`` is not HTML.
    """
    rows = [
        replace(
            r,
            dataset=md_text(r.dataset),
            method=md_text(r.method),
            degradation=md_text(r.degradation),
            reason=None if r.reason is None else md_text(r.reason),
        )
        for r in rows
    ]
    failed = None if failed is None else [md_text(f) for f in failed]
    pct = f"{CONFIDENCE:.0%}"
    lines = [
        "# Every method against the odometry it was given",
        "",
        "For each dataset, method and perturbation (odometry degradation, wrong laser offset or scan dropout; seeds "
        "pooled): the method's ATE and that of the "
        "odometry the same runs were given, both after their own rigid SE(2) alignment to the reference; their "
        f"ratio (< 1: the method improved on its odometry) with a {pct} paired moving-block bootstrap interval over "
        f"scans ({RESAMPLES} resamples, blocks of 1/{BLOCKS} of a run, the same scans for both); **worse** / "
        f"**better** when the whole interval is above / below 1, else *indistinguishable*. RPE@10 m and loop gap: "
        "the method's / the odometry method's cell of the same data, means over the seeds both have (ratio in "
        "brackets). Method: "
        "`albot1/report/generalisation.py`.",
        "",
        LEGEND,
        "",
        f"Regenerate: `{regenerate or regenerate_command(plan)}`.",
        "",
        "## Where a method is worse than its own odometry",
        "",
    ]
    worse = [r for r in rows if r.verdict == "worse"]
    if worse:
        lines += ["| method | dataset | degradation | seeds | ATE (m) | odometry ATE (m) | ratio | interval |"]
        lines += ["|---|---|---|---:|---:|---:|---:|---|"]
        lines += [
            f"| {marked(r.method, r.held_in)} | {r.dataset} | {r.degradation} | {_seeds(r)} | {_num(r.ate_m)} | "
            f"{_num(r.odometry_ate_m)} | {_ratio(r.ratio, d)} | {_ratio(r.ratio_low, d)}–{_ratio(r.ratio_high, d)} |"
            for r in worse
            for d in (ratio_digits(r.ratio_low, r.ratio_high),)
        ]
    else:
        lines.append(f"Nowhere at {pct} confidence.")
    # above 1 by more than rounding, each with the digits that show it above 1 (1.0004 read "1" at 3 digits)
    above = [r for r in rows if r.verdict == "indistinguishable" and r.ratio > 1.0 + RATIO_TIE]
    lines += _listing(
        "Ratio above 1 but not significantly",
        [
            f"{r.method} on {r.dataset} ({r.degradation}) {_ratio(r.ratio, ratio_digits(r.ratio, r.ratio))}"
            for r in above
        ],
    )
    lines += [
        "",
        "## Per method",
        "",
        f"| method | cells | of them held-in ({MARK}) | better | indistinguishable | worse | median ATE ratio "
        "| largest ratio (where) |",
        "|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    compared = [r for r in rows if r.verdict not in (PERFECT, NOT_APPLICABLE)]
    for method in dict.fromkeys(r.method for r in compared):
        mine = [r for r in compared if r.method == method]
        top = max(mine, key=lambda r: r.ratio)
        counts = [sum(r.verdict == v for r in mine) for v in ("better", "indistinguishable", "worse")]
        tuned = sum(bool(r.held_in) for r in mine)
        lines.append(
            f"| {method} | {len(mine)} | {tuned} | {counts[0]} | {counts[1]} | {counts[2]} | "
            f"{_ratio(median(r.ratio for r in mine))} | {_ratio(top.ratio)} ({top.dataset}, {top.degradation}) |"
        )
    uncompared = [r for r in rows if r.verdict == NOT_APPLICABLE]
    lines += _listing(
        "Not compared (no paired comparison applies)",
        [f"{r.method} on {r.dataset} ({r.degradation}): {r.reason}" for r in uncompared],
    )
    perfect = [r for r in rows if r.verdict == PERFECT]
    if perfect:
        # One column per dataset and perturbation: a perturbation of the set-up that leaves the odometry exact
        # (scan dropout) is a column of its own, never folded into the undisturbed run's.
        logs = list(dict.fromkeys((r.dataset, r.degradation) for r in perfect))
        lines += [
            "",
            "## With perfect odometry",
            "",
            "ATE (m) of each method given the reference poses as odometry (no ratio: the odometry's is 0), "
            "undisturbed and under each perturbation that leaves the odometry exact (seeds pooled). Which of "
            "these differ significantly: the paired comparisons against the best method under each "
            "dataset's table in `metrics.md` (`paired.csv`).",
            "",
            "| method | " + " | ".join(d if g == "none" else f"{d} ({g})" for d, g in logs) + " |",
            "|---|" + "---:|" * len(logs),
        ]
        for method in dict.fromkeys(r.method for r in perfect):
            by = {(r.dataset, r.degradation): r for r in perfect if r.method == method}
            lines.append(
                f"| {method} | "
                + " | ".join(marked(_num(by[d].ate_m), by[d].held_in) if d in by else "–" for d in logs)
                + " |"
            )
    for dataset in dict.fromkeys(r.dataset for r in rows):
        lines += [
            "",
            f"## {dataset}",
            "",
            "| method | degradation | seeds | ATE (m) | odometry ATE (m) | ratio [interval] | verdict "
            "| RPE@10 m (m), method / odometry | loop gap (m), method / odometry |",
            "|---|---|---:|---:|---:|---|---|---|---|",
        ]
        for r in (r for r in rows if r.dataset == dataset):
            lines.append(
                f"| {marked(r.method, r.held_in)} | {r.degradation} | {_seeds(r)} | {_num(r.ate_m)} | "
                f"{_num(r.odometry_ate_m)} | {_interval(r)} | {_verdict(r)} | "
                f"{_pair(r.rpe10_m, r.odometry_rpe10_m)} | {_pair(r.loop_gap_m, r.odometry_loop_gap_m)} |"
            )
    if failed:
        lines += [
            "",
            "## No completed run",
            "",
            "Every seed failed (reasons: the report's README): " + "; ".join(failed) + ".",
        ]
    lines.append("")
    return "\n".join(lines)


def _csv(rows: list[Comparison]) -> str:
    names = [f.name for f in fields(Comparison)]
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(names)
    for row in rows:
        values: list[Any] = [getattr(row, name) for name in names]
        # no ratio (perfect odometry, n/a: the reason column says why) is an empty cell, never "nan"
        writer.writerow(
            [
                ""
                if v is None or (isinstance(v, float) and not math.isfinite(v))
                else (f"{v:.9g}" if isinstance(v, float) else v)
                for v in values
            ]
        )
    return buffer.getvalue()


def write_generalisation(
    plan: GridPlan, records: list[CellRecord], out: Path, results_dir: Path | None = None
) -> tuple[Path, Path] | None:
    """Write ``generalisation.md`` and ``.csv`` into ``out`` when any run can be compared with its odometry.

    ``results_dir``: the store the records were read from, as given (its "Regenerate" line names it).
    """
    rows = comparisons(records)
    if not rows:
        return None
    page, table = out / PAGE, out / TABLE
    text = render_page(plan, rows, failed_groups(records), regenerate=regenerate_command(plan, results_dir, out))
    atomic_write(page, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    atomic_write(table, lambda tmp: tmp.write_text(_csv(rows), encoding="utf-8"))
    return page, table
