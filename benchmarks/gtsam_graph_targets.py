"""Measure the gtsam-graph targets of issue 4 on the full logs (a script, not a test: minutes of work).

Usage (from the checkout, with the dataset copies)::

    ALBOT1_DATA_DIR=/path/to/datasets .venv/bin/python benchmarks/gtsam_graph_targets.py \\
        [intel-corrected|aces|intel ...]

Prints one JSON line per run: the Intel corrected log with odometry degraded
by ``gauss:0.1:1`` for seeds 0, 1, 2 (ATE, rigid SE(2) alignment) with the
log's laser-pose odometry and with the catalog's default ``odom-segments``
odometry; ACES with ``aces.relations`` (relation metric); the full raw Intel
log (time). CPU seconds are printed beside wall seconds because the machine
may be shared.
"""

from __future__ import annotations

import json
import resource
import sys
import time
from typing import Any

from albot1.data.open import open_sequence
from albot1.metrics.ate import ate
from albot1.metrics.relations import relation_metric
from albot1.runs.execute import run_method


def _cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def _run(dataset: str, degradation: str = "none", seed: int = 0, **options: Any) -> dict[str, Any]:
    seq = open_sequence(dataset, **options).materialize()
    cpu, wall = _cpu_s(), time.perf_counter()
    result = run_method("gtsam-graph", seq, degradation=degradation, seed=seed, dataset_name=dataset)
    row: dict[str, Any] = {
        "dataset": dataset,
        "loader_options": options,
        "degradation": degradation,
        "seed": seed,
        "scans": len(result.poses),
        "wall_s": round(time.perf_counter() - wall, 2),
        "cpu_s": round(_cpu_s() - cpu, 2),
        "per_scan_ms_median": _round(result.timing().per_scan_ms_median, 3),
        "counters": result.counters,
    }
    if result.reference is not None:
        row["ate_rmse_m"] = round(ate(result.poses, result.reference)["rmse_m"], 4)
        row["odometry_ate_rmse_m"] = round(ate(result.odometry, result.reference)["rmse_m"], 4)
    if seq.relations is not None:
        for name, poses in (("relations", result.poses), ("odometry_relations", result.odometry)):
            block = relation_metric(result.timestamps, poses, seq.relations)
            row[name] = {
                "translation_m_mean": round(block["translation_m"]["mean"], 4),
                "rotation_deg_mean": round(block["rotation_deg"]["mean"], 3),
                "n": block["translation_m"]["n"],
            }
    return row


def main(targets: list[str]) -> None:
    if "intel-corrected" in targets:
        for odometry in ("laser-pose", "odom-segments"):
            for seed in (0, 1, 2):
                print(json.dumps(_run("intel-corrected", "gauss:0.1:1", seed, odometry=odometry)), flush=True)
    if "aces" in targets:
        print(json.dumps(_run("aces")), flush=True)
    if "intel" in targets:
        print(json.dumps(_run("intel")), flush=True)


def _round(value: float | None, digits: int) -> float | None:
    return None if value is None else round(value, digits)


if __name__ == "__main__":
    main(sys.argv[1:] or ["intel-corrected", "aces", "intel"])
