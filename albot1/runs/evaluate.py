"""Evaluation: a trajectory scored against its dataset's reference, into ``metrics.json``.

Two sources, one scoring function (:func:`score`), so a run folder and an
external trajectory holding the same poses get the same numbers digit for
digit:

* :func:`evaluate_run`: a run folder in, ``metrics.json`` written there. It
  reads the run with :func:`albot1.runs.folder.read_run` and reopens the
  dataset, degraded as the run was (:func:`reopen`), when a metric needs the
  scans (the map-shape metric's reference map).
* :func:`evaluate_trajectory`: a trajectory file from another tool (TUM,
  KITTI or a corrected CARMEN log; :mod:`albot1.data.trajectory`) scored
  against the reference poses and relations of a dataset
  (:mod:`albot1.runs.external` matches its poses to the scans). It has no
  map, no counters and no timing: those metrics are null with that reason.

The metrics are those of the metric registry (:mod:`albot1.metrics.registry`;
one module per metric in :mod:`albot1.metrics.measures`), each one top-level
key in registry order. When a metric cannot be computed its key is ``null``
and the key ``<metric>_reason`` beside it says why: the source lacks what it
needs (``Scored.absent``: no map, counters or timing for a trajectory file),
a need of the metric is unmet (no reference poses, no relations file, no
``places.json``...) or its inputs do not fit together (the error's message).
A computed metric never has a ``_reason`` key. Numbers are never invented to
fill a slot. The file is an :class:`albot1.metrics.record.MetricsRecord`: it is
validated against that model before it is written, so a metric whose block
does not match the documented fields fails here, not in a reader.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from albot1.data.open import open_as_run
from albot1.errors import Albot1Error
from albot1.metrics.errors import MetricsError
from albot1.metrics.record import MISSING_NOTE, MetricsRecord, build_metrics_record
from albot1.metrics.registry import MetricRegistry, metric_registry
from albot1.metrics.unit import MetricInputs
from albot1.records import RecordError, dump_record, parse_record
from albot1.runs.external import load_external
from albot1.runs.folder import METRICS_FILE, read_run, write_record
from albot1.runs.pair import check_time_offset, load_pair, parse_alignment, with_alignment
from albot1.runs.scored import Scored, scored_run
from albot1.settings import Settings

if TYPE_CHECKING:
    from albot1.data.model import Sequence


def evaluate_run(run_dir: Path, *, settings: Settings | None = None, opened: Sequence | None = None) -> MetricsRecord:
    """Compute every metric of the run in ``run_dir``, write ``metrics.json`` there, return it.

    ``opened``: the run's dataset as the caller opened it for the run (undegraded; :func:`reopen`), so that a
    metric needing the scans does not open the log a second time; the files' sha256 are checked all the same.
    """
    run = read_run(run_dir)
    source = f"{run.path / METRICS_FILE} (being written)"
    record = score(scored_run(run), settings=settings, source=source, opened=opened)
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
    time_offset_s: float | None = None,
    align: str | None = None,
) -> tuple[MetricsRecord, Scored]:
    """Score an external trajectory file against ``dataset``; write the metrics to ``out`` when given.

    Returns the record and what was scored (for evo result files and the
    CLI's note on poses left out). ``time_offset_s`` and ``align``: see :mod:`albot1.runs.pair`.
    """
    if align is not None:
        parse_alignment(align)  # refuse a bad choice before the dataset is read
    scored = load_external(
        path,
        dataset,
        format_name=format_name,
        label=label,
        max_dt_s=max_dt_s,
        settings=settings,
        wrap=wrap,
        time_offset_s=check_time_offset(time_offset_s),
    )
    scored = with_alignment(scored, align)
    record = score(scored, settings=settings, source=f"{out or path} (metrics being written)")
    if out is not None:
        write_record(out, record)
    return record, scored


def evaluate_pair(
    path: Path,
    reference: Path,
    *,
    out: Path | None = None,
    **options: Any,
) -> tuple[MetricsRecord, Scored]:
    """Score the trajectory file ``path`` against the reference trajectory file ``reference`` (no dataset).

    ``options``: those of :func:`albot1.runs.pair.load_pair`. Writes the metrics to ``out`` when given.
    """
    scored = load_pair(path, reference, **options)
    record = score(scored, source=f"{out or path} (metrics being written)")
    if out is not None:
        write_record(out, record)
    return record, scored


def score(
    scored: Scored,
    *,
    settings: Settings | None = None,
    source: str = "metrics",
    registry: MetricRegistry | None = None,
    opened: Sequence | None = None,
) -> MetricsRecord:
    """Every metric of ``registry`` (default: the project's) for ``scored``, as a validated record.

    A metric whose needs are not met, or whose inputs do not fit (an
    Albot1Error of its ``compute``), is null with the reason; ``source``
    names the file in errors. A block that does not fit its own model is the
    metric's bug and is raised (RecordError), never recorded as a reason.
    ``opened``: see :func:`evaluate_run`.
    """
    registry = registry or metric_registry()
    inputs = metric_inputs(scored, settings, opened)
    metrics: dict[str, Any] = {"run": scored.header, **scored.extra, "missing": MISSING_NOTE}
    for metric in registry:
        try:
            reason = scored.absent.get(metric.name) or metric.missing(inputs)
            if reason is None:
                metrics[metric.name] = dump_record(metric.compute(inputs))
                continue
        except RecordError:
            raise
        except Albot1Error as exc:
            reason = str(exc)
        metrics[metric.name], metrics[f"{metric.name}_reason"] = None, reason
    model = MetricsRecord if registry is metric_registry() else build_metrics_record(registry)
    return parse_record(model, metrics, source)


def metric_inputs(scored: Scored, settings: Settings | None = None, opened: Sequence | None = None) -> MetricInputs:
    """What the metrics compute from: ``scored``, with the dataset reopened on demand (``settings``; ``opened``)."""
    return MetricInputs(
        dataset=scored.dataset,
        timestamps=scored.timestamps,
        poses=scored.poses,
        reference=scored.reference,
        relations=scored.relations,
        relations_source=scored.relations_source,
        relation_timestamps=scored.relation_timestamps,
        relation_poses=scored.relation_poses,
        open_dataset=lambda: same_data(reopen(scored, settings, opened), scored),
        load_map=scored.load_map,
        counters=scored.counters,
        per_scan_ns=scored.per_scan_ns,
        timing=scored.timing,
        read_file=scored.read_file,
        alignment=scored.alignment,
        n_to_align=scored.n_to_align,
    )


def reopen(scored: Scored, settings: Settings | None = None, opened: Sequence | None = None) -> Sequence:
    """The dataset of ``scored`` as its run saw it: its degradation and seed applied (:func:`open_as_run`).

    Without them a ``dropout`` run's scans would be compared with every scan
    of the log, and the reference map would be refused as data that changed.
    ``opened``: the dataset already open (undegraded), not opened again: a bench cell evaluates the run it
    just made from the sequence it made it from (~15-100 ms of CPU a cell on a public log).
    """
    header = scored.header
    degradation, seed = header.get("degradation") or "none", header.get("seed")
    return open_as_run(scored.dataset, degradation, seed, settings=settings, opened=opened)


def same_data(sequence: Sequence, scored: Scored) -> Sequence:
    """``sequence`` when its files are the ones the run read (their sha256 in the run header), else MetricsError.

    A metric that reopens the dataset (the reference map) must not compare the
    run with data that changed since the run.
    """
    recorded = scored.header.get("data_sha256") or {}
    if recorded and sequence.metadata.checksums != recorded:
        raise MetricsError(
            f"dataset {scored.dataset!r}: its files' sha256 differ from the run's; the dataset changed since the run"
        )
    return sequence
