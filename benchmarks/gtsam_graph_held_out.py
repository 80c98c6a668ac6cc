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
apart"). ``--edges`` (cells with a reference) adds every sequential edge's and
loop closure's error against the reference: the heading RMS of the matched
edges, their lag-1 autocorrelation, the worst ones and every accepted closure
(docs/baselines.md, gtsam-graph, "why one run of edmonton swings"). ``--moves`` adds every tracked scan whose
match moved the odometry guess by more than 0.25 m, and which guess's match won (docs/baselines.md, gtsam-graph,
"sequential slides"). ``earned_odometry_match`` counts the earned choice's decisions (``odometry_trust_earned_level``;
docs/baselines.md, gtsam-graph, "the earned choice"). ``odometry_run_factors`` counts the odometry's factors over
runs of node steps (``odometry_trust_run_nodes``; docs/baselines.md, gtsam-graph, "edges spanning runs of steps").
``--stamp-jitter F`` adds Gaussian noise of F x the log's median positive scan period to every stamp (seeded by the
cell's seed; poses, odometry and scans untouched, ATE by scan index, relations dropped): a clock that lies, for
``track_velocity_time_scaled`` (docs/baselines.md, gtsam-graph, "the velocity guess scaled by elapsed time").
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from typing import Any

import numpy as np

from albot1.data.model import Sequence
from albot1.data.open import open_sequence
from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph import backend, frontend, odometry_trust
from albot1.metrics.ate import ate
from albot1.metrics.relations import relation_metric
from albot1.runs.execute import run_method

#: Bins of the odometry's heading step per node (deg) for ``--innovations`` (14.3 = half a node's rotation step).
TURN_BINS_DEG = (0.0, 2.0, 5.0, 10.0, 14.3239, 20.0, 30.0, math.inf)
#: A sequential edge stating a heading sigma of this or more is an odometry fallback, not a match (fallback: 10 deg).
FALLBACK_SIGMA_DEG = 5.0


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


def parse_cell(cell: str) -> tuple[str, str, int]:
    """``DATASET[|DEGRADATION[|SEED]]`` -> (dataset, degradation, seed): the cell form of these scripts' arguments."""
    dataset, _, rest = cell.partition("|")
    degradation, _, seed = rest.partition("|")
    return dataset, degradation or "none", int(seed or 0)


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


@contextmanager
def recorded_edges() -> Iterator[dict[str, list[tuple[Any, ...]]]]:
    """Every sequential edge (relative pose, stated sigmas) and accepted loop closure, while the block runs."""
    seen: dict[str, list[tuple[Any, ...]]] = {"sequential": [], "loops": []}
    add_node, add_loops = backend.BackEnd.add_node, backend.BackEnd.add_loops

    def node(self: backend.BackEnd, odometry: Any, step: Any, relative: Any, covariance: Any, *rest: Any) -> int:
        seen["sequential"].append((np.array(relative, dtype=float), np.sqrt(np.diag(covariance))))
        return add_node(self, odometry, step, relative, covariance, *rest)

    def loops(self: backend.BackEnd, accepted: Any) -> None:
        seen["loops"].extend(
            (m.current, m.candidate, np.array(m.relative), np.sqrt(np.diag(m.covariance))) for m in accepted
        )
        add_loops(self, accepted)

    backend.BackEnd.add_node = node  # type: ignore[method-assign,assignment]
    backend.BackEnd.add_loops = loops  # type: ignore[method-assign]
    try:
        yield seen
    finally:
        backend.BackEnd.add_node = add_node  # type: ignore[method-assign]
        backend.BackEnd.add_loops = add_loops  # type: ignore[method-assign]


@contextmanager
def recorded_moves(min_m: float = 0.25) -> Iterator[list[dict[str, Any]]]:
    """Every tracked scan whose passing match moved the odometry guess by more than ``min_m``, while the block runs:
    its scan count, the odometry step, the move, and which guess's match won against which fits (``--moves``)."""
    seen: list[dict[str, Any]] = []
    follow, attempt = frontend.FrontEnd.follow, frontend.FrontEnd.attempt
    tried: list[tuple[Any, ...]] = []
    scans = [0]

    def attempting(self: frontend.FrontEnd, target: Any, points: Any, guess: Any, *rest: Any, **named: Any) -> Any:
        out = attempt(self, target, points, guess, *rest, **named)
        tried.append(out)
        return out

    def following(self: frontend.FrontEnd, guess: Any, increment: Any, points: Any) -> Any:
        tried.clear()
        scans[0] += 1
        reg = follow(self, guess, increment, points)
        if reg is not None:
            move = se2.between(guess, reg.pose)
            if math.hypot(move[0], move[1]) > min_m:
                seen.append(
                    {
                        "scan": scans[0],
                        "odometry_step_m": round(math.hypot(increment[0], increment[1]), 3),
                        "move_m": round(math.hypot(move[0], move[1]), 3),
                        "won": "odometry guess" if tried and tried[0][0] is reg else "velocity guess",
                        "fitness": [None if t[0] is None else round(t[0].fitness, 3) for t in tried],
                        "passed": [bool(t[1]) for t in tried],
                    }
                )
        return reg

    frontend.FrontEnd.follow = following  # type: ignore[method-assign]
    frontend.FrontEnd.attempt = attempting  # type: ignore[method-assign]
    try:
        yield seen
    finally:
        frontend.FrontEnd.follow = follow  # type: ignore[method-assign]
        frontend.FrontEnd.attempt = attempt  # type: ignore[method-assign]


def edge_table(seen: dict[str, list[tuple[Any, ...]]], truth: np.ndarray, worst: int = 8) -> dict[str, Any]:
    """Sequential edges' and loop closures' errors against ``truth`` (the reference at the node scans), deg and m.

    A sequential edge whose stated heading sigma is at the fallback's
    (odometry, not a match) is left out of the RMS and the autocorrelation.
    """
    rows = []
    for key, (relative, sigma) in enumerate(seen["sequential"], start=1):
        true = se2.between(truth[key - 1], truth[key])
        error = se2.between(true, relative)
        rows.append((key, math.degrees(true[2]), math.degrees(error[2]), math.degrees(sigma[2])))
    table = np.array(rows, dtype=float).reshape(-1, 4)
    matched = table[table[:, 3] < FALLBACK_SIGMA_DEG]
    heading = matched[:, 2] - matched[:, 2].mean() if len(matched) else matched[:, 2]
    lag1 = float(np.corrcoef(heading[:-1], heading[1:])[0, 1]) if len(heading) > 2 else None
    order = np.argsort(-np.abs(matched[:, 2]))[:worst]
    loops = []
    for current, candidate, relative, sigma in seen["loops"]:
        error = se2.between(se2.between(truth[candidate], truth[current]), relative)
        loops.append(
            {
                "nodes": [int(current), int(candidate)],
                "error_m": round(math.hypot(error[0], error[1]), 3),
                "error_deg": round(math.degrees(error[2]), 2),
                "stated_m": round(float(max(sigma[0], sigma[1])), 3),
            }
        )
    return {
        "matched_heading_rms_deg": round(float(np.sqrt(np.mean(matched[:, 2] ** 2))), 3) if len(matched) else None,
        "lag1_autocorrelation": None if lag1 is None else round(lag1, 3),
        "worst": [
            {"node": int(k), "turn_deg": round(t, 1), "error_deg": round(e, 2), "stated_deg": round(sd, 2)}
            for k, t, e, sd in matched[order]
        ],
        "loops": loops,
    }


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


def jittered(seq: Sequence, fraction: float, seed: int) -> tuple[Sequence, dict[str, Any]]:
    """``seq`` with every stamp moved by Gaussian noise of ``fraction`` x its median positive scan period.

    The relations are dropped (they are matched to poses by stamp, so they would score a different pairing).
    """
    frames = list(seq.frames())
    stamps = np.array([f.scan.timestamp for f in frames], dtype=float)
    steps = np.diff(stamps)
    period = float(np.median(steps[steps > 0])) if (steps > 0).any() else 0.0
    noisy = stamps + np.random.default_rng(seed).normal(0.0, fraction * period, len(frames))
    moved = [replace(f, scan=replace(f.scan, timestamp=float(t))) for f, t in zip(frames, noisy, strict=True)]
    behind = int((np.diff(noisy) <= 0).sum())
    info = {"jitter_sigma_s": round(fraction * period, 3), "stamps_not_after_previous": behind}
    return Sequence.from_frames(seq.name, moved, seq.metadata, None), info


def measure(
    cell: str,
    overrides: dict[str, Any],
    innovations: bool = False,
    edges: bool = False,
    moves: bool = False,
    stamp_jitter: float = 0.0,
) -> dict[str, Any]:
    """Run gtsam-graph on one cell and score it (with ``innovations``: the odometry trust's heading innovations too;
    with ``edges``: the edges' errors against the reference, :func:`edge_table`; with ``moves``: the tracked scans
    whose match moved the odometry guess far, :func:`recorded_moves`)."""
    dataset, degradation, seed = parse_cell(cell)
    seq = open_sequence(dataset).materialize()
    jitter: dict[str, Any] = {}
    if stamp_jitter > 0:
        seq, jitter = jittered(seq, stamp_jitter, seed)
    wall, cpu = time.perf_counter(), time.process_time()
    with recorded_innovations() as seen, recorded_edges() as graph_edges, recorded_moves() as moved:
        result = run_method(
            "gtsam-graph", seq, overrides=overrides, degradation=degradation, seed=seed, dataset_name=dataset
        )
    row: dict[str, Any] = {
        "cell": cell,
        "wall_s": round(time.perf_counter() - wall, 1),
        "cpu_s": round(time.process_time() - cpu, 1),
        "odometry_factors": result.counters.get("odometry_fused"),
        "odometry_run_factors": result.counters.get("odometry_run_factors"),
        "loop_closures": result.counters.get("loop_closures_accepted"),
        "place_closures": result.counters.get("place_closures_accepted"),
        "velocity_matches": result.counters.get("tracking_velocity_guess"),
        "slides_refused": result.counters.get("tracking_velocity_slides_refused"),
        "velocity_time_scaled": result.counters.get("tracking_velocity_time_scaled"),
        "earned_odometry_match": [result.counters.get(f"odometry_earned_{k}", 0) for k in ("odometry", "match")],
        **jitter,
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
    if moves:
        row["moves"] = moved
    if innovations:
        row["innovations"] = innovation_table(seen)
    if edges and result.reference is not None:
        truth = np.asarray(result.reference, dtype=float)[np.asarray(result.extras["node_scans"], dtype=np.int64)]
        row["edges"] = edge_table(graph_edges, truth)
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument(
        "--innovations", action="store_true", help="also the heading innovations by turn (docs/baselines.md)"
    )
    parser.add_argument(
        "--edges", action="store_true", help="also the edges' errors against the reference (docs/baselines.md)"
    )
    parser.add_argument(
        "--moves", action="store_true", help="also the tracked scans whose match moved the odometry guess > 0.25 m"
    )
    parser.add_argument(
        "--stamp-jitter", type=float, default=0.0, metavar="F", help="stamps moved by F x the median scan period"
    )
    parser.add_argument("cells", nargs="+")
    args = parser.parse_args()
    overrides = {key: _value(value) for key, _, value in (s.partition("=") for s in args.settings)}
    for cell in args.cells:
        row = measure(cell, overrides, args.innovations, args.edges, args.moves, args.stamp_jitter)
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
