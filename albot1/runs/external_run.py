"""Another system's trajectory file stored as a run folder, so reports show it beside the methods run.

A suite's external method (``trajectories = "runs/carto/{dataset}.tum"``,
:mod:`albot1.bench.external`) runs nothing. Its cell scores the file
through the external-trajectory path (:func:`albot1.runs.external.load_external`
then :func:`albot1.runs.evaluate.score`: the poses matched to the scans,
every metric that applies, map / update counts / cost null with their
reason) and writes a run folder like any method's: ``trajectory.tum`` (the
matched poses), ``odometry.tum`` and ``reference.tum`` of the same scans,
``relations.txt``, ``result.json`` and ``metrics.json``. ``result.json``
says ``preset = "external"``; its ``config`` names the file, its format and
its sha256 (also in ``metrics.json`` ``trajectory``). Its timing block is
zeros because the record requires numbers: no time was measured, and the
report's cost columns show "not measured" for an external run
(:data:`EXTERNAL_PRESET`), never these zeros. The map is empty.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from albot1 import versions
from albot1.contract import MapData, RunResult
from albot1.data.open import open_sequence
from albot1.data.trajectory import read_trajectory
from albot1.runs.errors import RunError
from albot1.runs.evaluate import score
from albot1.runs.external import MAX_DT_S, load_external, match_by_time
from albot1.runs.folder import EXTERNAL_PRESET, METRICS_FILE, PreviewRenderer, write_record, write_run
from albot1.settings import Settings

__all__ = ["EXTERNAL_PRESET", "external_config", "write_external_run"]


def external_config(path: Path, format_name: str | None, sha256: str) -> dict[str, Any]:
    """The ``config`` of an external run: what identifies the scored file (part of the run key)."""
    return {"trajectory": str(path), "format": format_name, "sha256": sha256}


def write_external_run(
    *,
    path: Path,
    format_name: str | None,
    dataset: str,
    method: str,
    config: dict[str, Any],
    seed: int,
    runs_root: Path,
    settings: Settings | None = None,
    preview: PreviewRenderer | None = None,
) -> Path:
    """Score ``path`` against ``dataset`` and store it under ``runs_root/<key>``; returns the run folder.

    ``config`` is the planned one (:func:`external_config`): a file whose
    sha256 changed since planning is refused, as its key would lie.
    """
    scored = load_external(path, dataset, format_name=format_name, label=method, settings=settings)
    block = scored.extra["trajectory"]
    if block["sha256"] != config.get("sha256"):
        raise RunError(
            f"{path}: sha256 {block['sha256']} differs from {config.get('sha256')} when the grid was planned; "
            "the file changed during the run (plan again)"
        )
    sequence = open_sequence(dataset, settings=settings)
    arrays = sequence.arrays
    file = read_trajectory(path, format_name)
    if file.timestamps is None:
        scans = np.arange(len(arrays.timestamps))
    else:
        dt = block["max_dt_s"] if block["max_dt_s"] is not None else MAX_DT_S
        scans = match_by_time(file.timestamps, arrays.timestamps, dt).scan_index
    result = RunResult(
        method=method,
        dataset=dataset,
        preset=EXTERNAL_PRESET,
        degradation="none",
        seed=seed,
        config=config,
        timestamps=scored.timestamps,
        poses=scored.poses,
        odometry=arrays.odometry[scans],
        reference=scored.reference,
        relations=scored.relations,
        map=MapData(points=np.empty((0, 2))),
        counters={},
        extras={"external": block},
        per_scan_ns=np.empty(0, dtype=np.int64),
        finish_s=0.0,
        total_s=0.0,
        wall_s=0.0,
        peak_mb=0.0,
        # the libraries that read the log and compute the metrics (in the key: albot1.bench.external)
        versions=versions.run_versions(),
        dataset_info={
            "source": str(path),
            "format": block["format"],
            "odometry_source": "",
            "reference_source": "",
            # the files its reference poses and relations come from (in the key, as for a method's run)
            "data_sha256": dict(sequence.metadata.checksums),
            "manifest_loader": dict(sequence.metadata.manifest_loader),
        },
    )
    run_dir = write_run(result, runs_root, preview=preview)
    scored.header["key"] = run_dir.name  # the run folder's key, as for a method's run
    record = score(scored, settings=settings, source=f"{run_dir / METRICS_FILE} (being written)")
    write_record(run_dir / METRICS_FILE, record)
    return run_dir
