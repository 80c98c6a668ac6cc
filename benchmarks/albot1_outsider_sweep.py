"""An outsider's sweep of the Albot1 family on cells no suite runs (issue 21, session 23; a script, not a test).

Usage (from the checkout, with the dataset copies)::

    ALBOT1_DATA_DIR=/path/to/datasets .venv/bin/python benchmarks/albot1_outsider_sweep.py [--grid NAME ...]
    ALBOT1_DATA_DIR=... .venv/bin/python benchmarks/albot1_outsider_sweep.py --attribute \\
        'orebro-corrected?odometry=laser-pose[::5]|bias:0.05:0|0'

The first form runs the grids of docs/albot1-mapper.md, "An outsider's sweep, session 23" (``--grid``: some of
them; ``--list``: their names and sizes) and prints one JSON line per cell: the ATE RMSE (rigid) of the method
and of the odometry it was given and their ratio where the cell has reference poses, the mean relation error of
both where it has relations only, whether every pose and map segment is finite, the largest step by which the
estimate moved further than the odometry between two scans (``max_step_excess_m``, at which scan), and a
failure's message. ``albot1 run`` / ``albot1 evaluate --json`` (and ``albot1 run odometry``) give the same ATE one
cell at a time; the sub-range cells ``NAME[200:800]`` (a START the dataset references refuse: only prefixes exist)
are ``NAME[:800]`` with the first 200 scans left out here, in memory.

``--attribute CELL`` (``DATASET|DEGRADATION|SEED``, Albot1+ only) runs one cell and sums each step's error
against the reference step by what made the pose: ``kept`` (the ambiguity test kept the prediction), ``fused``
(the fit fused with the prediction), ``turnbound`` (the turn bound re-solved it), each ``/lm`` (a landmark placed
the robot) or ``/0lm`` (no landmark did: the starts were the prediction turned by -30..+30 deg). It patches
``Albot1Mapper._robust_pose`` in this process only, to read the localiser's counters around each call.
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from typing import Any

import numpy as np

from albot1.contract import RunResult
from albot1.data.model import Frame, Sequence
from albot1.data.open import open_sequence
from albot1.errors import Albot1Error
from albot1.geometry import se2
from albot1.methods.albot1.mapping import mapper as albot1_mapper
from albot1.metrics.ate import ate
from albot1.metrics.relations import relation_metric
from albot1.runs.execute import run_method

#: The perturbations of the corrected logs (none of them in benchmarks/generalisation.toml), with their seed.
PERTURBATIONS = (
    ("bias:-0.03:-0.7", 0),
    ("bias:0.05:0", 0),
    ("gauss:0.1:1", 0),
    ("gauss:0.02:5", 0),
    ("offset:-0.1:0.1:-3", 0),
    ("dropout:0.3", 0),
    ("dropout:0.7", 1),
)
#: SLAM-corrected logs not in the generalisation suite (csail and intel are the same drives as held-in raw logs).
LOGS = ("csail", "acapulco", "orebro", "freiburg-101", "freiburg-campus", "intel", "infinite-corridor")
SYNTHETIC = (
    "synthetic-corridor",
    "synthetic-office-loop",
    "synthetic-office-startstop",
    "synthetic-office-startstop-10deg",
    "synthetic-places-loop",
    "synthetic-places-double-loop",
    "synthetic-square-startstop",
)
#: Cells whose name carries this suffix skip the first scans of ``NAME[:800]`` (see the module's docstring).
SKIPPED_SCANS = 200

Cell = dict[str, Any]


def corrected(log: str) -> str:
    """The corrected log with its corrected poses as odometry (the perturbation is the odometry's only error)."""
    return f"{log}-corrected?odometry=laser-pose"


def _cell(dataset: str, degradation: str, seed: int = 0, preset: str = "plus", method: str = "albot1") -> Cell:
    return {"dataset": dataset, "method": method, "preset": preset, "degradation": degradation, "seed": seed}


def grids() -> dict[str, list[Cell]]:
    """Every grid of the sweep by name, in the order they were run."""
    whole = [_cell(corrected(log), d, s) for log in LOGS for d, s in PERTURBATIONS]
    strided: list[Cell] = []
    for log in ("csail", "orebro", "intel", "freiburg-101", "acapulco"):
        strided += [
            _cell(corrected(log) + "[::2]", "bias:0.05:0"),
            _cell(corrected(log) + "[::2]", "gauss:0.1:1", 1),
            _cell(corrected(log) + "[::5]", "bias:-0.03:-0.7"),
            _cell(corrected(log) + "[::5]", "none"),
        ]
    sub_ranges = [
        _cell(corrected(log) + "[:800]", d, s) | {"skip": SKIPPED_SCANS}
        for log in ("intel", "acapulco", "infinite-corridor", "freiburg-campus")
        for d, s in (("gauss:0.1:1", 2), ("bias:0.05:0", 0))
    ]
    odd = (("offset:-0.1:0.1:-3", 0), ("dropout:0.7", 1), ("gauss:0.02:5", 0), ("bias:0.05:0", 0))
    synthetic = [_cell(world, d, s) for world in SYNTHETIC for d, s in odd]
    raw = [
        _cell(log, d)
        for log in ("aces[:1500]", "intel[::4]", "fr079[::3]", "mit-csail[:1000]", "fr-clinic[::5]")
        for d in ("none", "gauss:0.02:5")
    ]
    seeds = []
    for log in ("acapulco", "orebro", "freiburg-101", "infinite-corridor", "freiburg-campus"):
        seeds += [_cell(corrected(log), d, s) for d in ("gauss:0.1:1", "gauss:0.02:5") for s in (1, 2)]
        seeds += [
            _cell(corrected(log) + "[::5]", "bias:0.05:0"),
            _cell(corrected(log) + "[::2]", "offset:-0.1:0.1:-3"),
        ]
    faithful = [
        _cell(dataset, d, s, preset)
        for preset in ("literal", "thesis", "exact")
        for dataset, d, s in (
            *((corrected(log), d, s) for log in ("csail", "orebro", "freiburg-101", "intel") for d, s in odd),
            *((world, d, s) for world in SYNTHETIC[:2] + SYNTHETIC[-1:] for d, s in odd[1:3]),
            *((log, "gauss:0.02:5", 0) for log in ("aces[:1500]", "intel[::4]")),
            *((corrected(log), d, 0) for log in ("acapulco", "freiburg-campus", "infinite-corridor")
              for d in ("gauss:0.1:1", "bias:-0.03:-0.7")),
        )
    ]  # fmt: skip
    places_worlds = ("synthetic-places-loop", "synthetic-places-double-loop", "synthetic-office-loop")
    places = [
        _cell(world, d, s, "default", "albot1-places")
        for world in (*places_worlds, corrected("csail"), corrected("freiburg-101"))
        for d, s in odd
    ]
    places += [
        _cell(world, d, s, "default", "albot1-places")
        for world in (corrected("intel"), corrected("infinite-corridor"), "aces[:1500]", *SYNTHETIC[4:5], SYNTHETIC[0])
        for d, s in (("bias:-0.03:-0.7", 0), ("dropout:0.3", 2))
    ]
    extra = [
        _cell(corrected("orebro"), "dropout:0.7", 1, "plus", "albot1-places"),
        _cell(corrected("freiburg-101") + "[::5]", "offset:-0.1:0.1:-3", 0, "plus", "albot1-places"),
        _cell("synthetic-places-double-loop", "gauss:0.02:5", 0, "plus", "albot1-places"),
        _cell("synthetic-places-loop", "bias:-0.03:-0.7", 0, "exact", "albot1-places"),
        _cell("synthetic-places-loop", "dropout:0.7", 2, "literal", "albot1-places"),
        _cell("synthetic-office-long[:4000]", "dropout:0.7"),
        _cell("synthetic-office-long[:4000]", "gauss:0.1:1", 0, "literal"),
        _cell("aces[:1500]?odometry=reference", "gauss:0.1:1"),  # a clean refusal: aces has no reference poses
        _cell("fr-clinic[:2000]", "offset:-0.1:0.1:-3"),
        _cell("fr-clinic[:2000]", "dropout:0.3", 0, "thesis"),
    ]
    extreme = [
        _cell(dataset, d, s, preset)
        for preset in ("plus", "thesis", "literal", "exact")
        for dataset in ("synthetic-office-loop", corrected("freiburg-101"))
        for d, s in (("bias:1:0", 0), ("gauss:1:30", 0), ("offset:1:1:90", 0), ("dropout:0.95", 3), ("bias:0:45", 0))
    ]
    extreme += [
        _cell("synthetic-places-loop", d, s, preset, "albot1-places")
        for d, s in (("gauss:1:30", 0), ("dropout:0.95", 3))
        for preset in ("default", "plus")
    ]
    return {
        "whole": whole,
        "strided": strided,
        "sub-ranges": sub_ranges,
        "synthetic": synthetic,
        "raw": raw,
        "seeds": seeds,
        "faithful": faithful,
        "places": places,
        "extra": extra,
        "extreme": extreme,
    }


def open_cell(cell: Cell) -> Sequence:
    """The cell's sequence, with its first ``skip`` scans left out (renumbered from 0) when it has one."""
    sequence = open_sequence(cell["dataset"])
    skip = int(cell.get("skip", 0))
    if not skip:
        return sequence

    def later(frames: Iterator[Frame]) -> Iterator[Frame]:
        for i, frame in enumerate(frames):
            if i >= skip:
                yield replace(frame, index=i - skip)

    return sequence.with_frames(later)


def _steps(poses: np.ndarray) -> np.ndarray:
    """Each scan's step from the one before, in the earlier pose's frame (x, y, heading)."""
    return np.asarray(se2.between(poses[:-1], poses[1:]), dtype=float)


def sanity(result: RunResult) -> dict[str, Any]:
    """Finite poses and map, and the largest step the estimate took beyond the odometry's (a jump's size)."""
    poses = np.asarray(result.poses, dtype=float)
    odometry = np.asarray(result.odometry, dtype=float)
    segments = result.map.segments
    out: dict[str, Any] = {
        "finite_poses": bool(np.isfinite(poses).all()),
        "finite_map": bool(segments is None or np.isfinite(np.asarray(segments)).all()),
    }
    if len(poses) > 1 and out["finite_poses"]:
        excess = np.hypot(*_steps(poses)[:, :2].T) - np.hypot(*_steps(odometry)[:, :2].T)
        worst = int(np.argmax(excess))
        out["max_step_excess_m"] = float(excess[worst])
        out["max_step_excess_at"] = worst + 1
    return out


def measure(cell: Cell) -> dict[str, Any]:
    """Run one cell; its scores against the odometry it was given, its sanity, or its failure's message."""
    record: dict[str, Any] = dict(cell)
    start = time.perf_counter()
    try:
        result = run_method(
            cell["method"],
            open_cell(cell),
            preset=cell["preset"],
            degradation=cell["degradation"],
            seed=cell["seed"],
            dataset_name=cell["dataset"],
        )
    except Albot1Error as exc:  # a method's or a loader's own error: the finding is its message
        record["error"] = f"{type(exc).__name__}: {exc}"
        return record
    record["scans"] = len(result.poses)
    record.update(sanity(result))
    if result.reference is not None:
        reference = np.asarray(result.reference, dtype=float)
        record["ate_m"] = ate(result.poses, reference)["rmse_m"]
        record["odometry_ate_m"] = ate(result.odometry, reference)["rmse_m"]
        if record["odometry_ate_m"] > 0.0:
            record["ratio"] = record["ate_m"] / record["odometry_ate_m"]
    elif result.relations is not None:
        for key, poses in (("relation_m", result.poses), ("odometry_relation_m", result.odometry)):
            block = relation_metric(result.timestamps, poses, result.relations, outside="exclude")
            record[key] = block["translation_m"]["mean"]
        record["ratio"] = record["relation_m"] / record["odometry_relation_m"]
    record["wall_s"] = round(time.perf_counter() - start, 1)
    return record


@contextmanager
def branch_log() -> Iterator[dict[int, str]]:
    """Scan -> what made Albot1+'s pose there (see the module's docstring), while the context is open."""
    log: dict[int, str] = {}
    original = albot1_mapper.Albot1Mapper._robust_pose

    def robust_pose(self: Any, rl: Any, prev_pose: Any, step: Any) -> Any:
        plus = self._plus
        before = (plus.ambiguous_views, plus.turn_bounded_views)
        pose, reference = original(self, rl, prev_pose, step)
        kept, bounded = plus.ambiguous_views != before[0], plus.turn_bounded_views != before[1]
        kind = "kept" if kept else ("turnbound" if bounded else "fused")
        log[self._n] = kind + ("/0lm" if reference is None else "/lm")
        return pose, reference

    albot1_mapper.Albot1Mapper._robust_pose = robust_pose  # type: ignore[method-assign]
    try:
        yield log
    finally:
        albot1_mapper.Albot1Mapper._robust_pose = original  # type: ignore[method-assign]


def attribute(text: str) -> dict[str, Any]:
    """Albot1+'s step errors against the reference on one cell, summed by what made each pose."""
    dataset, degradation, seed = (text.split("|") + ["none", "0"])[:3]
    with branch_log() as log:
        result = run_method("albot1", open_sequence(dataset), preset="plus", degradation=degradation, seed=int(seed))
    if result.reference is None:
        raise SystemExit(f"{dataset}: no reference poses to attribute the error against")
    poses, odometry, reference = (np.asarray(a, dtype=float) for a in (result.poses, result.odometry, result.reference))
    error, odometry_error = _steps(poses) - _steps(reference), _steps(odometry) - _steps(reference)
    sums: dict[str, list[float]] = collections.defaultdict(lambda: [0, 0.0, 0.0, 0.0, 0.0])
    for i in range(len(error)):
        row = sums[log.get(i + 1, "odometry-step")]
        heading = math.degrees(float(se2.wrap(error[i, 2])))
        row[0] += 1
        row[1] += heading
        row[2] += abs(heading)
        row[3] += math.hypot(error[i, 0], error[i, 1])
        row[4] += math.hypot(odometry_error[i, 0], odometry_error[i, 1])
    keys = (
        "steps",
        "heading_error_sum_deg",
        "abs_heading_error_sum_deg",
        "position_error_sum_m",
        "odometry_position_error_sum_m",
    )
    return {
        "cell": text,
        "ate_m": ate(poses, reference)["rmse_m"],
        "odometry_ate_m": ate(odometry, reference)["rmse_m"],
        "by_branch": {branch: dict(zip(keys, row, strict=True)) for branch, row in sorted(sums.items())},
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", action="append", help="run only this grid (repeatable; --list names them)")
    parser.add_argument("--list", action="store_true", help="list the grids and their sizes")
    parser.add_argument("--attribute", metavar="CELL", help="attribute one Albot1+ cell's step errors by branch")
    args = parser.parse_args()
    if args.attribute:
        print(json.dumps(attribute(args.attribute)))
        return
    every = grids()
    if args.list:
        for name, cells in every.items():
            print(name, len(cells))
        return
    for name in args.grid or list(every):
        for cell in every[name]:
            print(json.dumps({"grid": name, **measure(cell)}), flush=True)


if __name__ == "__main__":
    main()
