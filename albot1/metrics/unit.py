"""What a metric is: a typed block, what it needs, how it is computed, its headline and its report columns.

Why a unit: a metric used to be spread over its maths, the evaluation
function, three names in the records module, an ``isinstance`` ladder in the
CLI and the report's column list. Now one module per metric
(:mod:`albot1.metrics.measures`) declares one :class:`Metric`, and every
reader takes what it needs from the registry (:mod:`albot1.metrics.registry`):

* :func:`albot1.runs.evaluate.score` computes each metric whose
  :class:`Need` s are met, and records the first unmet need's reason
  otherwise (never a made-up number);
* the metrics record (:class:`albot1.metrics.record.MetricsRecord`) validates
  each block of ``metrics.json`` with the metric's models;
* ``albot1 evaluate`` prints the metric's :attr:`Metric.headline`;
* the report's accuracy table has the metric's :attr:`Metric.columns`.

``Metric`` is generic in its block type, so mypy checks that ``compute``
returns the block that ``headline`` and the columns' ``applies`` take.

What a metric may need is described by :class:`MetricInputs`: the scored
trajectory, the dataset's reference, and what the run left (map, counters,
timing, a method's own files). A metric never opens a file or a dataset
itself: the evaluation passes callables that do (``open_dataset``,
``read_file``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Generic, Literal, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray

from albot1.data.degrade import SCAN_DROPOUT
from albot1.errors import Albot1Error
from albot1.geometry.types import FloatArray
from albot1.records import Record, Timing

if TYPE_CHECKING:
    from albot1.contract import MapData
    from albot1.data.model import Relations, Sequence

BlockT = TypeVar("BlockT", bound=Record)
OtherT = TypeVar("OtherT", bound=Record)

NO_REFERENCE = "the dataset has no reference poses"


@dataclass(frozen=True)
class MetricInputs:
    """Everything a metric may be computed from (one evaluation; built by :mod:`albot1.runs.evaluate`).

    ``timestamps``/``poses``/``reference`` are aligned row by row (one row
    per scan scored). ``relation_timestamps``/``relation_poses`` are the poses
    the relation metric looks relations up in. ``load_map``, ``counters``,
    ``per_scan_ns``/``timing`` and ``read_file`` are None when the source has
    none (an external trajectory). ``open_dataset`` reopens the dataset (a
    metric that needs its scans or metadata); it raises an Albot1Error when
    the dataset cannot be opened.
    """

    dataset: str
    timestamps: FloatArray
    poses: FloatArray
    reference: FloatArray | None
    relations: Relations | None
    relations_source: str
    relation_timestamps: FloatArray
    relation_poses: FloatArray
    open_dataset: Callable[[], Sequence]
    load_map: Callable[[], MapData] | None = None
    counters: Mapping[str, int | float] | None = None
    per_scan_ns: NDArray[np.int64] | None = None
    timing: Timing | None = None
    #: a method's own output file of the run folder by name (``places.json``): its JSON content, or None
    #: when the run has no such file (None for a source without a run folder)
    read_file: Callable[[str], object | None] | None = None
    #: how the ``ate`` metric aligns the estimate (``albot1 evaluate --align``; every other metric is
    #: alignment-free or aligns on its own terms): the method, and the first N pairs it is estimated on
    alignment: Literal["none", "first", "rigid"] = "rigid"
    n_to_align: int | None = None
    #: answers worked out once per evaluation (whether the route is declared closed, ...)
    memo: dict[str, object] = field(default_factory=dict, compare=False, repr=False)


@dataclass(frozen=True)
class Need:
    """One thing a metric needs; ``missing`` is the reason recorded when ``present`` says it is absent."""

    what: str
    missing: str
    present: Callable[[MetricInputs], bool]


def route_declared_closed(inputs: MetricInputs) -> bool:
    """Whether the scored poses cover a whole route the dataset declares closed (``closed_loop`` metadata).

    Only then may the end-to-start gap be reported without reference poses:
    the reference offset is zero by declaration, not by assumption. A run
    on a prefix of a closed route does not end at its start, nor need one
    whose scans a dropout thinned (``dropout:P``). Counting the
    dataset's scans is free for the synthetic worlds (the ones that declare
    closed routes) and a full pass for a streamed log, so the answer is
    worked out once per evaluation.
    """
    if "closed_route" not in inputs.memo:
        try:
            sequence = inputs.open_dataset()
            extra = sequence.metadata.extra
            # A scan dropout may have left the route's last scans out: its kept scans need not end at the start.
            closed = (
                bool(extra.get("closed_loop", False))
                and SCAN_DROPOUT not in extra
                and sequence.count_scans() == len(inputs.poses)
            )
        except Albot1Error:
            closed = False
        inputs.memo["closed_route"] = closed
    return bool(inputs.memo["closed_route"])


REFERENCE = Need("reference poses", NO_REFERENCE, lambda i: i.reference is not None)
RELATIONS = Need(
    "ground-truth relations", "the dataset has no ground-truth relations", lambda i: i.relations is not None
)
MAP = Need("the run's map", "no map to compare", lambda i: i.load_map is not None)
COUNTERS = Need("the method's counters", "no counters of the method", lambda i: i.counters is not None)
TIMING = Need("per-scan timings", "no per-scan timings", lambda i: i.per_scan_ns is not None)
RETURNING_ROUTE = Need(
    "reference poses or a route declared closed",
    f"{NO_REFERENCE}, and the route is not known to be closed",
    lambda i: i.reference is not None or route_declared_closed(i),
)


def method_file(name: str, missing: str) -> Need:
    """The need of a method's own output file ``name`` of the run folder (e.g. ``places.json``)."""
    return Need(f"the method's {name}", missing, lambda i: i.read_file is not None and i.read_file(name) is not None)


class BlockLookup(Protocol):
    """Another metric's block of the same run (what :class:`albot1.metrics.record.MetricsRecord` offers)."""

    def get(self, metric: Metric[OtherT]) -> OtherT | None: ...


@dataclass(frozen=True)
class ColumnSpec(Generic[BlockT]):
    """One report column of a metric: the number at ``path`` in its block (or in ``result.json``).

    ``source="result"`` reads ``result.json`` (a method's own counter shown
    beside the metric that judges it). ``applies`` may declare the number not
    applicable to a run although it was computed (a loop gap on a route that
    never returns): it returns the reason, or None when the number applies.
    ``undefined`` says why the number can be null in a computed block (a
    ratio without a denominator), for the report's not-applicable notes.
    """

    key: str
    path: str
    header: str
    source: Literal["block", "result"] = "block"
    applies: Callable[[BlockT, BlockLookup], str | None] | None = None
    undefined: str | None = None


@dataclass(frozen=True)
class Metric(Generic[BlockT]):
    """One metric of ``metrics.json``: its key, its place in the file, its block models, needs and functions.

    ``models`` are the block's alternatives (most metrics have one; the
    loop gap has a second without reference poses); ``position`` orders the
    keys of ``metrics.json`` (unique; the registry checks). ``compute`` may
    raise an Albot1Error when the inputs do not fit: the message becomes the
    metric's reason.
    """

    name: str
    position: int
    models: tuple[type[BlockT], ...]
    needs: tuple[Need, ...]
    compute: Callable[[MetricInputs], BlockT]
    headline: Callable[[BlockT], str]
    columns: tuple[ColumnSpec[BlockT], ...] = ()

    def missing(self, inputs: MetricInputs) -> str | None:
        """The reason of the first unmet need, or None when every need is met."""
        for need in self.needs:
            if not need.present(inputs):
                return need.missing
        return None
