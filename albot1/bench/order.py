"""The order the runner starts cells in: the longest expected first.

With ``-j N`` workers taking cells from one queue, a long cell started near
the end of the grid runs alone while the other workers sit idle (a 107 s
gtsam-graph cell started last would add ~50 s to a 2-worker grid). Starting
the cells in decreasing expected cost (LPT, longest processing time first)
leaves at most the shortest cells for the end.

The expected cost of a cell is the wall time its earlier attempts took
(``attempt.json``, or ``FAILED.json`` for a failed one) in this results
folder, matched on what the cell runs
(method entry, preset, overrides, dataset slice, degradation, seed) but not
on the code version: a code change plans new keys, yet costs move little.
A cell never seen costs the median of its method entry's known cells, else
the median of all known cells. With nothing known (a fresh clone) the plan's
order is kept. The suites beside it (``results/*``) are not read: they share
few cells (6 of the thesis suite's 93 with the default suite, none of the
generalisation suite's), so reading their hundreds of folders would cost
more than it orders. The order changes no result: every cell runs in its own
process from its own inputs, and the report reads the store, not the order.
"""

from __future__ import annotations

import json
import os
import statistics
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from albot1.bench.grid import Cell
from albot1.bench.store import ATTEMPT, CELL, FAILED
from albot1.bench.store_records import read_json_file
from albot1.records import RecordError

#: What a cell's cost is matched on (its run's inputs but for the code version and resolved config).
Signature = tuple[str, str, str, str, str, str, int]


def signature(description: dict[str, Any]) -> Signature | None:
    """The match key of a cell description (``cell.json`` / :meth:`Cell.to_json`); None if it lacks a field."""
    try:
        return (
            str(description["method_label"]),
            str(description["preset"]),
            json.dumps(description.get("overrides") or {}, sort_keys=True, default=str),
            str(description["dataset_label"]),
            str(description["degradation"]),
            str(description.get("trajectory") or ""),
            int(description["seed"]),
        )
    except (KeyError, TypeError, ValueError):
        return None


def _read(path: Path) -> Any:
    """The store's reader (:func:`read_json_file`); None where it refuses: this only orders cells."""
    try:
        return read_json_file(path, "cell record")
    except RecordError:
        return None


def _elapsed(run_dir: Path) -> float | None:
    """The wall time of the folder's last attempt (s), None when none is recorded."""
    for name in (ATTEMPT, FAILED):
        record = _read(run_dir / name)
        if isinstance(record, dict):
            value = record.get("elapsed_s")
            if isinstance(value, (int, float)) and value > 0:
                return float(value)
    return None


def past_costs(stores: Iterable[Path]) -> dict[Signature, float]:
    """Wall time per cell signature from the run folders of ``stores`` (results folders); the newest attempt wins.

    Unreadable or partial folders are passed over: this only orders cells.
    """
    found: dict[Signature, tuple[float, float]] = {}  # signature -> (mtime of cell.json, elapsed)
    for store in stores:
        try:
            entries = list(os.scandir(store / "runs"))
        except OSError:
            continue
        for entry in entries:
            run_dir = Path(entry.path)
            try:
                mtime = (run_dir / CELL).stat().st_mtime
            except OSError:
                continue
            description = _read(run_dir / CELL)
            key = signature(description) if isinstance(description, dict) else None
            elapsed = _elapsed(run_dir) if key is not None else None
            if key is None or elapsed is None:
                continue
            if key not in found or mtime > found[key][0]:
                found[key] = (mtime, elapsed)
    return {key: elapsed for key, (_, elapsed) in found.items()}


def _known_cost(cell: Cell, known: dict[Signature, float]) -> float | None:
    key = signature(cell.to_json())
    return None if key is None else known.get(key)


def expected_costs(cells: list[Cell], known: dict[Signature, float]) -> list[float] | None:
    """Each cell's expected wall time (s), in the order of ``cells``; None when nothing about them is known."""
    own = [_known_cost(cell, known) for cell in cells]
    seen = [cost for cost in own if cost is not None]
    if not seen:
        return None
    by_method: dict[str, list[float]] = {}
    for cell, cost in zip(cells, own, strict=True):
        if cost is not None:
            by_method.setdefault(cell.method_label, []).append(cost)
    overall = statistics.median(seen)
    return [
        cost if cost is not None else statistics.median(by_method.get(cell.method_label) or [overall])
        for cell, cost in zip(cells, own, strict=True)
    ]


def longest_first(cells: list[Cell], known: dict[Signature, float]) -> list[Cell]:
    """``cells`` in decreasing expected cost (ties keep the plan's order); unchanged when no cost is known."""
    costs = expected_costs(cells, known)
    if costs is None:
        return list(cells)
    order = sorted(range(len(cells)), key=lambda index: -costs[index])  # sorted is stable: ties keep plan order
    return [cells[index] for index in order]
