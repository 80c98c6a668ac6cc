"""Evaluation: a trajectory scored against its dataset's reference, into ``metrics.json``.

Two sources, one scoring function (:func:`score`), so a run folder and an
external trajectory holding the same poses get the same numbers digit for
digit:

* :func:`evaluate_run`: a run folder in, ``metrics.json`` written there. It
  reads the run with :func:`albot1.runs.folder.read_run` and reopens the
  dataset when the map-shape metric needs the scans.
* :func:`evaluate_trajectory`: a trajectory file from another tool (TUM,
  KITTI or a corrected CARMEN log; :mod:`albot1.data.trajectory`) scored
  against the reference poses and relations of a dataset
  (:mod:`albot1.runs.external` matches its poses to the scans). It has no
  map, no counters and no timing: those metrics are null with that reason.

Missing metrics. Every metric has one top-level key (``ate``,
``ate_windows``, ``rpe``, ``drift``, ``loop_gap``, ``orientation``,
``relations``, ``map_shape``, ``updates``, ``cost``). When a metric cannot be computed its key is ``null`` and the key
``<metric>_reason`` beside it says why (no reference poses, no relations
file, the dataset cannot be opened, inputs that do not fit together...).
The relation metric scores the relations whose two scans the run saw and
says how many it left out (``relations_total``, ``relations_used``,
``relations_outside_run``).
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
from numpy.typing import NDArray

from albot1.data.open import open_sequence
from albot1.data.transforms import head
from albot1.errors import Albot1Error
from albot1.geometry import se2
from albot1.metrics.alignment import describe, rigid_transform
from albot1.metrics.ate import ate, windowed_ate
from albot1.metrics.cost import cost
from albot1.metrics.drift import drift
from albot1.metrics.errors import MetricsError
from albot1.metrics.loop_gap import pair_gaps, route_gap
from albot1.metrics.map_shape import map_agreement
from albot1.metrics.orientation import orientation_table
from albot1.metrics.relations import relation_metric
from albot1.metrics.rpe import rpe_set
from albot1.metrics.updates import update_counts
from albot1.records import (
    METRIC_NAMES,
    MISSING_NOTE,
    MetricName,
    MetricsRecord,
    dump_record,
    parse_record,
)
from albot1.runs.external import load_external
from albot1.runs.folder import METRICS_FILE, read_run, write_record
from albot1.runs.scored import Scored, scored_run
from albot1.settings import Settings

if TYPE_CHECKING:
    from albot1.data.model import Sequence

#: The metrics of ``metrics.json`` in file order (defined once, by the record model).
METRIC_KEYS: tuple[MetricName, ...] = METRIC_NAMES

NO_REFERENCE = "the dataset has no reference poses"


def evaluate_run(run_dir: Path, *, settings: Settings | None = None) -> MetricsRecord:
    """Compute every metric of the run in ``run_dir``, write ``metrics.json`` there, return it."""
    run = read_run(run_dir)
    record = score(scored_run(run), settings=settings, source=f"{run.path / METRICS_FILE} (being written)")
    write_record(run.path / METRICS_FILE, record)
    return record


def evaluate_trajectory(
    path: Path,
    dataset: str,
    *,
    format_name: str | None = None,
    label: str | None = None,
    max_dt_s: float | None = None,
    settings: Settings | None = None,
    out: Path | None = None,
    wrap: Callable[[Sequence], Sequence] | None = None,
) -> tuple[MetricsRecord, Scored]:
    """Score an external trajectory file against ``dataset``; write the metrics to ``out`` when given.

    Returns the record and what was scored (for evo result files and the
    CLI's note on poses left out).
    """
    scored = load_external(
        path, dataset, format_name=format_name, label=label, max_dt_s=max_dt_s, settings=settings, wrap=wrap
    )
    record = score(scored, settings=settings, source=f"{out or path} (metrics being written)")
    if out is not None:
        write_record(out, record)
    return record, scored


def score(scored: Scored, *, settings: Settings | None = None, source: str = "metrics") -> MetricsRecord:
    """Every metric of ``scored`` as a validated :class:`MetricsRecord` (``source`` names it in errors)."""
    ref = scored.reference
    poses = scored.poses
    metrics: dict[str, Any] = {"run": scored.header, **scored.extra, "missing": MISSING_NOTE}

    def put(key: str, compute: Callable[[], dict[str, Any]], missing: str | None = None) -> None:
        missing = scored.absent.get(key, missing)
        if missing is not None:
            metrics[key], metrics[f"{key}_reason"] = None, missing
            return
        try:
            metrics[key] = compute()
        except Albot1Error as exc:
            metrics[key], metrics[f"{key}_reason"] = None, str(exc)

    if ref is None:
        for name in ("ate", "ate_windows", "rpe", "drift", "orientation"):
            put(name, dict, NO_REFERENCE)
        if _known_closed(scored.dataset, len(poses), settings):
            put(
                "loop_gap",
                lambda: {
                    "units": {"gap": "m", "heading": "deg"},
                    "alignment": "none (relative poses)",
                    "route": route_gap(poses, None),
                    "pairs": None,
                    "pairs_reason": NO_REFERENCE,
                },
            )
        else:
            put("loop_gap", dict, f"{NO_REFERENCE}, and the route is not known to be closed")
    else:
        reference: NDArray[np.float64] = ref
        put("ate", lambda: ate(poses, reference))
        put("ate_windows", lambda: windowed_ate(poses, reference))
        put("rpe", lambda: rpe_set(poses, reference))
        put("drift", lambda: drift(poses, reference))
        put(
            "loop_gap",
            lambda: {
                "units": {"gap": "m", "heading": "deg"},
                "alignment": "none (relative poses)",
                "route": route_gap(poses, reference),
                **pair_gaps(scored.timestamps, poses, reference),
            },
        )
        put("orientation", lambda: orientation_table(poses, reference, scored.timestamps))

    # A run folder keeps every relation of its dataset, whether from `albot1 run` or a bench cell; the ones
    # the run's scans cannot score (a slice: a prefix, every n-th scan) are left out here, by the one rule
    # (albot1.data.relations.relations_in_run), and counted in the block (relations_outside_run).
    relations = scored.relations
    put(
        "relations",
        lambda: relation_metric(
            scored.relation_timestamps,
            scored.relation_poses,
            relations,  # type: ignore[arg-type]
            outside="exclude",
            source=scored.relations_source,
        ),
        None if relations is not None else "the dataset has no ground-truth relations",
    )

    put("map_shape", lambda: _map_shape(scored, settings), None if ref is not None else NO_REFERENCE)
    counters = scored.counters
    put("updates", lambda: update_counts(dict(counters or {})))
    per_scan_ns, timing = scored.per_scan_ns, scored.timing
    put(
        "cost",
        lambda: cost(per_scan_ns, dump_record(timing) if timing is not None else {}),  # type: ignore[arg-type]
        None if per_scan_ns is not None else "no per-scan timings",
    )

    return parse_record(MetricsRecord, metrics, source)


def _known_closed(dataset: str, scans: int, settings: Settings | None) -> bool:
    """Whether ``scans`` poses cover a whole route ``dataset`` declares closed (``closed_loop`` metadata).

    Only then may the end-to-start gap be reported without reference poses:
    the reference offset is zero by declaration, not by assumption. A run
    on a prefix of a closed route does not end at its start. Counting the
    dataset's scans is free for the synthetic worlds (the ones that declare
    closed routes) and a full pass for a streamed log.
    """
    try:
        sequence = open_sequence(dataset, settings=settings)
    except Albot1Error:
        return False
    return bool(sequence.metadata.extra.get("closed_loop", False)) and sequence.count_scans() == scans


def _map_shape(scored: Scored, settings: Settings | None) -> dict[str, Any]:
    """Reopen the dataset, project its scans with the reference poses and compare with the map."""
    reference, dataset = scored.reference, scored.dataset
    if reference is None:
        raise MetricsError(NO_REFERENCE)
    if scored.load_map is None:
        raise MetricsError("no map to compare")
    n = int(len(scored.poses))
    try:
        sequence = head(open_sequence(dataset, settings=settings), n)
    except Albot1Error as exc:
        raise MetricsError(f"cannot reopen dataset {dataset!r} for the reference map: {exc}") from exc
    recorded = scored.header.get("data_sha256") or {}
    if recorded and sequence.metadata.checksums != recorded:  # the scans on disk are not the ones the run read
        raise MetricsError(
            f"dataset {dataset!r}: its files' sha256 differ from the run's; the dataset changed since the run"
        )
    offset = np.asarray(sequence.metadata.sensor_offset, dtype=float)
    parts: list[np.ndarray] = []
    count = 0
    for frame in sequence.frames():
        k = frame.index
        if k >= n:
            break
        if abs(frame.scan.timestamp - scored.timestamps[k]) > 1e-3:
            raise MetricsError(
                f"dataset {dataset!r} scan {k} has time {frame.scan.timestamp:.6f} but the "
                f"run's trajectory has {scored.timestamps[k]:.6f}; the dataset changed since the run"
            )
        sensor = se2.compose(reference[k], offset)
        parts.append(se2.transform_points(sensor, frame.scan.points()))
        count += 1
    if count != n:
        raise MetricsError(f"dataset {dataset!r} has {count} scans, the run has {n}")
    transform = rigid_transform(scored.poses, reference)
    map_points = se2.transform_points(transform, scored.load_map().geometry_points())
    block = map_agreement(map_points, np.concatenate(parts) if parts else np.empty((0, 2)))
    return {
        "units": {"distance": "m", "precision": "fraction", "coverage": "fraction"},
        "alignment": "rigid",
        "alignment_transform": describe(transform, "rigid"),
        "reference_map": "every scan projected with its reference pose (and the sensor offset)",
        **block,
    }
