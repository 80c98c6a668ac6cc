"""Measure gtsam-graph on cells of issue 21's generalisation suite (a script, not a test: minutes of work).

Usage (from the checkout, with the dataset copies)::

    ALBOT1_DATA_DIR=/path/to/datasets .venv/bin/python benchmarks/gtsam_graph_held_out.py \\
        [--set KEY=VALUE ...] [--innovations] CELL [CELL ...]

A CELL is ``DATASET`` or ``DATASET|DEGRADATION`` or ``DATASET|DEGRADATION|SEED``,
e.g. ``'edmonton-corrected?odometry=laser-pose[::3]|gauss:0.05:2|1'``, a
synthetic world or a raw log (``aces``). Prints one JSON line per cell: ATE
RMSE of the method and of the odometry it was given and their ratio (where
the cell has a reference), the relation metric (where it has relations),
the odometry factors added and the closures accepted. This is how the
tables of docs/baselines.md (gtsam-graph, "the accumulated bias and a
weight floor") were measured; ``albot1 run`` / ``albot1 evaluate`` give the
same numbers one cell at a time. ``--innovations`` adds the heading
innovations (odometry step minus match) of every matched node step, by how
far the step's odometry turns (docs/baselines.md, gtsam-graph, "turns learnt
apart").
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from albot1.data.open import open_sequence
from albot1.methods.baselines.gtsam_graph import odometry_trust
from albot1.metrics.ate import ate
from albot1.metrics.relations import relation_metric
from albot1.runs.execute import run_method

#: Bins of the odometry's heading step per node (deg) for ``--innovations`` (14.3 = half a node's rotation step).
TURN_BINS_DEG = (0.0, 2.0, 5.0, 10.0, 14.3239, 20.0, 30.0, math.inf)


def _value(text: str) -> Any:
    """``true``/``false``, an int, a float, else the string (as ``--set`` on the CLI)."""
    if text in ("true", "false"):
        return text == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


@contextmanager
def recorded_innovations() -> Iterator[list[tuple[float, float]]]:
    """Every matched node step's (odometry heading step, heading innovation) in rad, while the block runs."""
    seen: list[tuple[float, float]] = []
    add = odometry_trust.OdometryTrust.add

    def recording(self: odometry_trust.OdometryTrust, odometry_step: Any, match_step: Any) -> None:
        seen.append((float(odometry_step[2]), float(odometry_trust.innovation(odometry_step, match_step)[2])))
        add(self, odometry_step, match_step)

    odometry_trust.OdometryTrust.add = recording  # type: ignore[method-assign]
    try:
        yield seen
    finally:
        odometry_trust.OdometryTrust.add = add  # type: ignore[method-assign]


def innovation_table(seen: list[tuple[float, float]]) -> list[dict[str, Any]]:
    """Per bin of |odometry heading step| (deg; None: no bound): steps, robust spread (1.4826 MAD), median, deg."""
    turn = np.degrees(np.abs([t for t, _ in seen]))
    inn = np.degrees([d for _, d in seen])
    rows = []
    for lo, hi in zip(TURN_BINS_DEG[:-1], TURN_BINS_DEG[1:], strict=True):
        h = inn[(turn >= lo) & (turn < hi)]
        if len(h):
            centre = float(np.median(h))
            spread = odometry_trust.MAD_TO_SIGMA * float(np.median(np.abs(h - centre)))
            rows.append(
                {
                    "turn_deg": [lo, hi if math.isfinite(hi) else None],
                    "steps": len(h),
                    "spread_deg": round(spread, 3),
                    "median_deg": round(centre, 3),
                }
            )
    return rows


def measure(cell: str, overrides: dict[str, Any], innovations: bool = False) -> dict[str, Any]:
    """Run gtsam-graph on one cell and score it (with ``innovations``: the odometry trust's heading innovations too)."""
    dataset, _, rest = cell.partition("|")
    degradation, _, seed = rest.partition("|")
    seq = open_sequence(dataset).materialize()
    wall = time.perf_counter()
    with recorded_innovations() as seen:
        result = run_method(
            "gtsam-graph",
            seq,
            overrides=overrides,
            degradation=degradation or "none",
            seed=int(seed or 0),
            dataset_name=dataset,
        )
    row: dict[str, Any] = {
        "cell": cell,
        "wall_s": round(time.perf_counter() - wall, 1),
        "odometry_factors": result.counters.get("odometry_fused"),
        "loop_closures": result.counters.get("loop_closures_accepted"),
        "place_closures": result.counters.get("place_closures_accepted"),
    }
    if result.reference is not None:
        graph = ate(result.poses, result.reference)["rmse_m"]
        odometry = ate(result.odometry, result.reference)["rmse_m"]
        row.update(ate_m=round(graph, 4), odometry_ate_m=round(odometry, 4))
        row["ratio"] = round(graph / odometry, 3) if odometry > 0 else None  # perfect odometry: no ratio
    if seq.relations is not None:
        block = relation_metric(result.timestamps, result.poses, seq.relations)
        row["relations_m"] = round(block["translation_m"]["mean"], 4)
        row["relations_deg"] = round(block["rotation_deg"]["mean"], 3)
    if innovations:
        row["innovations"] = innovation_table(seen)
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument(
        "--innovations", action="store_true", help="also the heading innovations by turn (docs/baselines.md)"
    )
    parser.add_argument("cells", nargs="+")
    args = parser.parse_args()
    overrides = {key: _value(value) for key, _, value in (s.partition("=") for s in args.settings)}
    for cell in args.cells:
        print(json.dumps(measure(cell, overrides, args.innovations)), flush=True)


if __name__ == "__main__":
    main()
