"""Every verified loop match of a gtsam-graph run, with what the method measured and its error (analysis only).

Usage (from the checkout, with the dataset copies)::

    ALBOT1_DATA_DIR=/path/to/datasets .venv/bin/python benchmarks/gtsam_graph_closures.py CELL [KEY=VALUE ...]

Prints one JSON line for the run (ATE, closures accepted, rejections) and one per
match that passed the loop tests (loop closer or place recognition), accepted or
still waiting for its confirmation: the inlier fraction and RMS of its ICP, the
correction it implies for the current node, its Mahalanobis distance (3 dof) from
the graph's estimate at that moment (joint marginal covariance of the two nodes
from ``gtsam.Marginals`` over every factor, plus the match's own covariance), the
ambiguity of the coarse or place search where one ran, a probe correlative search
(+-2 m, +-15 deg) around the match's pose (its ambiguity and how far its best pose
lies from ICP's) and, from the reference poses, the match's error. The reference
is used here only, after the run, never by the method; the probes do not change
the run (same ATE). This is how docs/baselines.md (gtsam-graph, "which closures
are wrong with perfect odometry") was measured.
"""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import gtsam
import numpy as np

from albot1.data.open import open_sequence
from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph import backend, loop_closer, place_recognition
from albot1.methods.baselines.gtsam_graph.correlative import SearchWindow, correlative_search
from albot1.methods.baselines.gtsam_graph.graph import body_frame_covariance
from albot1.metrics.ate import ate
from albot1.runs.execute import run_method

PROBE = SearchWindow(half_width_m=2.0, step_m=0.2, half_angle_rad=math.radians(15), step_rad=math.radians(3))


class Recorder:
    """Wraps the loop closer's and place recognition's searches and matches while a run goes on."""

    def __init__(self) -> None:
        self.rows: list[dict[str, Any]] = []
        self.matches: list[Any] = []
        self.accepted: set[tuple[int, int]] = set()
        self.coarse: Any = None
        self.place: Any = None

    def install(self) -> None:
        cs, bb, lm, add = (
            loop_closer.correlative_search,
            place_recognition.branch_and_bound_search,
            loop_closer.loop_match,
            backend.BackEnd.add_loops,
        )

        def coarse(*a: Any, **k: Any) -> Any:
            self.coarse = cs(*a, **k)
            return self.coarse

        def place(*a: Any, **k: Any) -> Any:
            self.place = bb(*a, **k)
            return self.place

        def add_loops(back: Any, accepted: Any) -> None:
            self.accepted.update((m.current, m.candidate) for m in accepted)
            add(back, accepted)

        def matcher(source: str) -> Any:
            def match(back: Any, key: int, j: int, reg: Any, covariance: Any) -> Any:
                m = lm(back, key, j, reg, covariance)
                self.rows.append(self.describe(source, back, m, reg))
                self.matches.append(m)
                return m

            return match

        loop_closer.correlative_search = coarse  # type: ignore[assignment]
        place_recognition.branch_and_bound_search = place  # type: ignore[assignment]
        loop_closer.loop_match = matcher("loop")  # type: ignore[assignment]
        place_recognition.loop_match = matcher("place")  # type: ignore[assignment]
        backend.BackEnd.add_loops = add_loops  # type: ignore[method-assign]

    def describe(self, source: str, back: Any, m: Any, reg: Any) -> dict[str, Any]:
        key, j = m.current, m.candidate
        graph = back.graph
        joint = (
            gtsam.Marginals(graph._all_factors, graph._isam.calculateEstimate())
            .jointMarginalCovariance(gtsam.KeyVector([j, key]))
            .fullMatrix()
        )
        h = gtsam.Pose2(*back.estimates[j]).between(gtsam.Pose2(*back.estimates[key]))
        e = np.asarray(gtsam.Pose2(*m.relative).localCoordinates(h))
        jac = np.hstack([-np.asarray(h.inverse().AdjointMap()), np.eye(3)])
        relative_cov = jac @ joint @ jac.T
        loop_cov = body_frame_covariance(np.asarray(m.relative), m.covariance)
        cfg = back.config
        nodes = range(
            max(0, j - cfg.loop_submap_nodes), min(key - cfg.loop_min_node_gap, j + cfg.loop_submap_nodes) + 1
        )
        probe = correlative_search(back.target(nodes, j).points, back.scans[key], np.asarray(m.relative), PROBE)
        row: dict[str, Any] = {
            "source": source,
            "nodes": [int(key), int(j)],
            "fitness": round(float(reg.fitness), 3),
            "rmse_m": round(float(reg.rmse_m), 4),
            "correction_m": round(math.hypot(*m.correction[:2]), 3),
            "correction_deg": round(math.degrees(m.correction[2]), 2),
            "mahalanobis": round(float(e @ np.linalg.solve(relative_cov + loop_cov, e)), 2),
            "graph_sigma": [round(float(s), 4) for s in np.sqrt(np.diag(relative_cov))],
            "probe_ambiguity": round(float(probe.ambiguity), 3),
            "probe_offset_m": round(math.hypot(*(probe.pose[:2] - m.relative[:2])), 2),
        }
        if source == "loop" and self.coarse is not None:
            row["coarse_ambiguity"] = round(float(self.coarse.ambiguity), 3)
        if source == "place" and self.place is not None:
            row["place_ambiguity"] = round(float(self.place.ambiguity), 3)
            row["place_score"] = round(float(self.place.score), 3)
        self.coarse = None
        return row


def main() -> None:
    cell, settings = sys.argv[1], sys.argv[2:]
    overrides: dict[str, Any] = {}
    for text in settings:
        key, _, value = text.partition("=")
        overrides[key] = {"true": True, "false": False}.get(value, value)
        if isinstance(overrides[key], str):
            try:
                overrides[key] = float(value)
            except ValueError:
                pass
    recorder = Recorder()
    recorder.install()
    seq = open_sequence(cell).materialize()
    result = run_method("gtsam-graph", seq, overrides=overrides, dataset_name=cell)
    run = {
        "cell": cell,
        "ate_m": round(ate(result.poses, result.reference)["rmse_m"], 4) if result.reference is not None else None,
        "accepted": result.counters["loop_closures_accepted"],
        "rejections": result.extras["loop_rejections"],
    }
    print(json.dumps(run))
    truth = None
    if result.reference is not None:
        truth = np.asarray(result.reference, dtype=float)[np.asarray(result.extras["node_scans"], dtype=np.int64)]
    for row, m in zip(recorder.rows, recorder.matches, strict=True):
        row["accepted"] = (m.current, m.candidate) in recorder.accepted
        if truth is not None:
            error = se2.between(se2.between(truth[m.candidate], truth[m.current]), m.relative)
            row["error_m"] = round(math.hypot(error[0], error[1]), 3)
            row["error_deg"] = round(math.degrees(error[2]), 2)
        print(json.dumps(row))


if __name__ == "__main__":
    main()
