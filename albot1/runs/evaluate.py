"""``evaluate_run``: a run folder in, ``metrics.json`` out.

This is the only module of :mod:`albot1.metrics` that touches files: it
reads the run with :func:`albot1.runs.folder.read_run`, reopens the dataset
when the map-shape metric needs the scans, calls the pure metric functions
and writes ``metrics.json`` atomically.

Missing metrics. Every metric has one top-level key (``ate``,
``ate_windows``, ``rpe``, ``drift``, ``loop_gap``, ``orientation``,
``relations``, ``map_shape``, ``updates``, ``cost``). When a metric cannot be computed its key is ``null`` and the key
``<metric>_reason`` beside it says why (no reference poses, no relations
file, the dataset cannot be opened, inputs that do not fit together...).
A computed metric never has a ``_reason`` key. Numbers are never invented to
fill a slot. The file is an :class:`albot1.records.MetricsRecord`: it is
validated against that model before it is written, so a metric whose block
does not match the documented fields fails here, not in a reader.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from albot1.errors import Albot1Error
from albot1.metrics.errors import MetricsError
from albot1.records import (
    METRIC_NAMES,
    MISSING_NOTE,
    MetricName,
    MetricsRecord,
    ResultRecord,
    dump_record,
    parse_record,
)
from albot1.settings import Settings

if TYPE_CHECKING:
    from albot1.runs.folder import StoredRun

METRICS_FILE = "metrics.json"
#: The metrics of ``metrics.json`` in file order (defined once, by the record model).
METRIC_KEYS: tuple[MetricName, ...] = METRIC_NAMES

NO_REFERENCE = "the dataset has no reference poses"


def evaluate_run(run_dir: Path, *, settings: Settings | None = None) -> MetricsRecord:
    """Compute every metric of the run in ``run_dir``, write ``metrics.json`` there, return it."""
    from albot1.runs.folder import read_run, write_record

    run = read_run(run_dir)
    info = run.info
    ref = run.reference
    metrics: dict[str, Any] = {
        "run": {
            "key": info.key,
            "method": info.method,
            "dataset": info.dataset,
            "preset": info.preset,
            "degradation": info.degradation,
            "seed": info.seed,
            "scans": int(len(run.poses)),
            "has_reference": ref is not None,
        },
        "missing": MISSING_NOTE,
    }

    def put(key: str, compute: Callable[[], dict[str, Any]], missing: str | None = None) -> None:
        if missing is not None:
            metrics[key], metrics[f"{key}_reason"] = None, missing
            return
        try:
            metrics[key] = compute()
        except Albot1Error as exc:
            metrics[key], metrics[f"{key}_reason"] = None, str(exc)

    from albot1.metrics.ate import ate, windowed_ate
    from albot1.metrics.cost import cost
    from albot1.metrics.drift import drift
    from albot1.metrics.loop_gap import pair_gaps, route_gap
    from albot1.metrics.orientation import orientation_table
    from albot1.metrics.relations import relation_metric
    from albot1.metrics.rpe import rpe_set
    from albot1.metrics.updates import update_counts

    put("ate", lambda: ate(run.poses, ref), None if ref is not None else NO_REFERENCE)
    put("ate_windows", lambda: windowed_ate(run.poses, ref), None if ref is not None else NO_REFERENCE)
    put("rpe", lambda: rpe_set(run.poses, ref), None if ref is not None else NO_REFERENCE)
    put("drift", lambda: drift(run.poses, ref), None if ref is not None else NO_REFERENCE)

    if ref is not None:
        put(
            "loop_gap",
            lambda: {
                "units": {"gap": "m", "heading": "deg"},
                "alignment": "none (relative poses)",
                "route": route_gap(run.poses, ref),
                **pair_gaps(run.timestamps, run.poses, ref),
            },
        )
    elif _known_closed(info, len(run.poses), settings):
        put(
            "loop_gap",
            lambda: {
                "units": {"gap": "m", "heading": "deg"},
                "alignment": "none (relative poses)",
                "route": route_gap(run.poses, None),
                "pairs": None,
                "pairs_reason": NO_REFERENCE,
            },
        )
    else:
        put("loop_gap", lambda: {}, f"{NO_REFERENCE}, and the route is not known to be closed")

    put(
        "orientation",
        lambda: orientation_table(run.poses, ref, run.timestamps),
        None if ref is not None else NO_REFERENCE,
    )

    relations_file = run.path / "relations.txt"
    put(
        "relations",
        lambda: relation_metric(
            run.timestamps,
            run.poses,
            run.relations,  # type: ignore[arg-type]
            outside="exclude",
            source=str(relations_file),
        ),
        None if run.relations is not None else "the dataset has no ground-truth relations",
    )

    put("map_shape", lambda: _map_shape(run, settings), None if ref is not None else NO_REFERENCE)
    put("updates", lambda: update_counts(dict(info.counters)))
    put("cost", lambda: cost(run.per_scan_ns, dump_record(info.timing)))

    record = parse_record(MetricsRecord, metrics, f"{run.path / METRICS_FILE} (being written)")
    write_record(run.path / METRICS_FILE, record)
    return record


def _known_closed(info: ResultRecord, scans: int, settings: Settings | None) -> bool:
    """Whether the run covers a whole route its dataset declares closed (``closed_loop`` metadata).

    Only then may the end-to-start gap be reported without reference poses:
    the reference offset is zero by declaration, not by assumption. A run
    on a prefix of a closed route does not end at its start. Counting the
    dataset's scans is free for the synthetic worlds (the ones that declare
    closed routes) and a full pass for a streamed log.
    """
    from albot1.data.open import open_sequence

    try:
        sequence = open_sequence(info.dataset, settings=settings)
    except Albot1Error:
        return False
    return bool(sequence.metadata.extra.get("closed_loop", False)) and sequence.count_scans() == scans


def _map_shape(run: StoredRun, settings: Settings | None) -> dict[str, Any]:
    """Reopen the dataset, project its scans with the reference poses and compare with the run's map."""
    from albot1.data.open import open_sequence
    from albot1.data.transforms import head
    from albot1.geometry import se2
    from albot1.metrics.alignment import describe, rigid_transform
    from albot1.metrics.map_shape import map_agreement

    info, reference = run.info, run.reference
    if reference is None:
        raise MetricsError(NO_REFERENCE)
    n = int(len(run.poses))
    try:
        sequence = head(open_sequence(info.dataset, settings=settings), n)
    except Albot1Error as exc:
        raise MetricsError(f"cannot reopen dataset {info.dataset!r} for the reference map: {exc}") from exc
    offset = np.asarray(sequence.metadata.sensor_offset, dtype=float)
    parts: list[np.ndarray] = []
    count = 0
    for frame in sequence.frames():
        k = frame.index
        if k >= n:
            break
        if abs(frame.scan.timestamp - run.timestamps[k]) > 1e-3:
            raise MetricsError(
                f"dataset {info.dataset!r} scan {k} has time {frame.scan.timestamp:.6f} but the "
                f"run's trajectory has {run.timestamps[k]:.6f}; the dataset changed since the run"
            )
        sensor = se2.compose(reference[k], offset)
        parts.append(se2.transform_points(sensor, frame.scan.points()))
        count += 1
    if count != n:
        raise MetricsError(f"dataset {info.dataset!r} has {count} scans, the run has {n}")
    transform = rigid_transform(run.poses, reference)
    map_points = se2.transform_points(transform, run.load_map().geometry_points())
    block = map_agreement(map_points, np.concatenate(parts) if parts else np.empty((0, 2)))
    return {
        "units": {"distance": "m", "precision": "fraction", "coverage": "fraction"},
        "alignment": "rigid",
        "alignment_transform": describe(transform, "rigid"),
        "reference_map": "every scan projected with its reference pose (and the sensor offset)",
        **block,
    }
