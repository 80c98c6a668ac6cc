"""The terminal view of a running grid: a tqdm bar, failures as they happen, a summary table.

This is presentation, created by the CLI and handed to the runner as its
observer; the runner itself never writes to the terminal.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from typing import Any

from albot1.bench.grid import CellOutcome, GridPlan
from albot1.bench.runner import GridSummary


class TqdmProgress:
    """A progress bar over the grid; each failure is handed to ``write`` when it happens.

    The caller chooses where lines go; ``tqdm.write`` keeps them above the bar.
    """

    def __init__(self, write: Callable[[str], None], *, disable: bool = False) -> None:
        self._write = write
        self._disable = disable
        self._bar: Any = None
        self._failed = 0

    def started(self, total: int, cached: int) -> None:
        from tqdm import tqdm

        self._bar = tqdm(
            total=total, initial=cached, unit="cell", desc="bench", disable=self._disable, dynamic_ncols=True
        )
        if cached:
            self._write(f"{cached} of {total} cells already complete (kept)")

    def finished(self, outcome: CellOutcome) -> None:
        if outcome.status == "failed":
            self._failed += 1
            allowed = " (allowed by the suite)" if outcome.allowed else ""
            if outcome.kept:
                allowed = " (allowed by the suite; kept from an earlier run of this cell, --retry-failed runs it again)"
            self._write(f"FAILED{allowed} {outcome.description}: {outcome.reason}")
        if self._bar is not None and outcome.status != "cached":
            self._bar.update(1)
            self._bar.set_postfix(failed=self._failed, refresh=False)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()


def summary_table(summary: GridSummary) -> str:
    """A plain-text table: per method, cells done / kept / failed and the time spent."""
    rows: dict[str, dict[str, float]] = defaultdict(lambda: {"done": 0, "cached": 0, "failed": 0, "seconds": 0.0})
    for outcome in summary.outcomes:
        row = rows[outcome.method_label]
        row[outcome.status] += 1
        row["seconds"] += outcome.elapsed_s
    header = f"{'method':<22} {'ran':>5} {'kept':>5} {'failed':>6} {'cell-s':>8}"
    lines = [header, "-" * len(header)]
    for label in sorted(rows):
        r = rows[label]
        lines.append(
            f"{label:<22} {int(r['done']):>5} {int(r['cached']):>5} {int(r['failed']):>6} {r['seconds']:>8.1f}"
        )
    counts = summary.counts
    lines.append("-" * len(header))
    lines.append(
        f"{'total':<22} {counts['done']:>5} {counts['cached']:>5} {counts['failed']:>6} "
        f"{sum(o.elapsed_s for o in summary.outcomes):>8.1f}   wall {summary.wall_s:.1f} s"
    )
    return "\n".join(lines)


def plan_table(plan: GridPlan) -> str:
    """Planned cells per dataset (``--dry-run``), then what was skipped."""
    per_dataset: dict[str, dict[str, int]] = defaultdict(lambda: defaultdict(int))
    for cell in plan.cells:
        per_dataset[cell.dataset_label][cell.degradation] += 1
    lines = [f"suite {plan.suite}: {len(plan.cells)} cells"]
    for dataset, by_degradation in per_dataset.items():
        detail = ", ".join(f"{d} x{n}" for d, n in by_degradation.items())
        lines.append(f"  {dataset:<36} {sum(by_degradation.values()):>4}  ({detail})")
    lines += [f"  skipped dataset {s.name}: {s.reason}" for s in plan.skipped_datasets]
    lines += [f"  skipped method {s.name}: {s.reason}" for s in plan.skipped_methods]
    lines += [f"  config failure {key}: {reason}" for key, reason in plan.config_failures.items()]
    return "\n".join(lines)
