"""``metrics.json`` as a typed record, its metric keys taken from the metric registry.

Why built from the registry: a metric names its key, its block models and
its place in the file once, in its own module (:mod:`albot1.metrics.measures`);
the record gets one field ``<name>`` (the block or null) and one field
``<name>_reason`` per metric from there, in registry order, so the file keeps
its key order and no list of metrics is written out by hand. The class is
made once, at import, with pydantic's ``create_model``; mypy sees
:class:`MetricsRecordBase` (the fixed part and the typed accessors): a
block is read with ``record.get(METRIC)``, typed by the metric's block.

Conventions (``docs/metrics.md``): a metric that cannot be computed is
``null`` with ``<metric>_reason`` beside it; a computed one has no
``_reason`` key ("a block or a reason, never both, never neither"). A file
written before a metric existed lacks both keys: it is read as not applicable
with :data:`NOT_IN_FILE` as the reason (so older results folders stay
readable), and written back with that reason.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, ClassVar, Literal, TypeVar, Union

from pydantic import create_model, model_validator

from albot1.metrics.registry import MetricRegistry, metric_registry
from albot1.metrics.unit import Metric
from albot1.records import Count, OmitsAbsentReasons, Record, Sha256

BlockT = TypeVar("BlockT", bound=Record)

#: The ``missing`` note of ``metrics.json``: the not-applicable convention in words.
MISSING_NOTE = "a metric that cannot be computed is null and '<metric>_reason' beside it says why"
#: The reason of a metric a file lacks altogether (written by a version of the code before the metric existed).
NOT_IN_FILE = "not in this metrics.json: it was written before this metric existed (run albot1 evaluate again)"


class RunHeader(Record):
    """``metrics.json`` ``run``: which run the metrics belong to.

    For an external trajectory (``albot1 evaluate --trajectory``) ``method``
    is its label, ``preset`` is ``external``, ``seed`` is null (unknown) and
    ``scans`` counts the poses matched to the dataset's scans.
    """

    key: str
    method: str
    dataset: str
    preset: str
    degradation: str
    seed: int | None
    scans: Count
    has_reference: bool
    #: the sha256 of the dataset's files the run read (result.json ``dataset_info.data_sha256``); empty for a
    #: synthetic world, an external trajectory, and metrics written before it was recorded
    data_sha256: dict[str, Sha256] = {}


class TrajectorySource(OmitsAbsentReasons):
    """``metrics.json`` ``trajectory``: the external trajectory file an evaluation scored (absent for a run folder).

    Its poses are matched to the dataset's scans by time (the nearest scan
    within ``max_dt_s``; one pose per scan, the nearest) or, for a format
    without timestamps (KITTI), by order (``max_dt_s`` null). Poses left
    out are counted, never dropped silently: ``unmatched`` found no scan
    within ``max_dt_s``, ``duplicates`` lost their scan to a nearer pose.
    ``versions`` names the code that scored it.
    """

    file: str
    format: Literal["tum", "kitti", "carmen"]
    sha256: str
    poses: Count
    matched: Count
    unmatched: Count
    duplicates: Count
    max_dt_s: float | None
    versions: dict[str, str | None]
    #: reference poses (the dataset's scans, or the poses of ``reference_file``) that no pose of the file
    #: was matched to: scored metrics cover the others only (absent in files written before it was counted)
    reference_without_pose: int | None = None
    #: ``albot1 evaluate --reference FILE``: the reference trajectory file, its format, sha256 and pose count
    reference_file: str | None = None
    reference_format: Literal["tum", "kitti", "carmen"] | None = None
    reference_sha256: str | None = None
    reference_poses: int | None = None
    #: seconds added to the file's timestamps before matching (evo's ``--t_offset``); absent when 0
    time_offset_s: float | None = None
    #: the ATE alignment asked for on the command line (``se2``, ``origin``, ``first:N``, ``none``)
    alignment: str | None = None

    OMITTED_WHEN_NULL: ClassVar[frozenset[str]] = frozenset(
        {
            "reference_without_pose",
            "reference_file",
            "reference_format",
            "reference_sha256",
            "reference_poses",
            "time_offset_s",
            "alignment",
        }
    )


class MetricsRecordBase(OmitsAbsentReasons):
    """The fixed part of ``metrics.json`` and the typed access to its blocks (see the module's docstring).

    ``trajectory`` describes the scored file of an external trajectory and is
    absent from a run folder's metrics.
    """

    OMITTED_WHEN_NULL: ClassVar[frozenset[str]] = frozenset({"trajectory"})
    REGISTRY: ClassVar[MetricRegistry]

    run: RunHeader
    trajectory: TrajectorySource | None = None
    missing: str = MISSING_NOTE

    @model_validator(mode="before")
    @classmethod
    def _older_files(cls, data: Any) -> Any:
        """A metric the file lacks altogether is not applicable, with :data:`NOT_IN_FILE` as the reason."""
        if not isinstance(data, Mapping) or not hasattr(cls, "REGISTRY"):
            return data
        lacking = {
            f"{n}_reason": NOT_IN_FILE for n in cls.REGISTRY.names if n not in data and f"{n}_reason" not in data
        }
        return {**data, **lacking} if lacking else data

    @model_validator(mode="after")
    def _block_or_reason(self) -> MetricsRecordBase:
        for name in self.REGISTRY.names:
            has_block, has_reason = self.block(name) is not None, self.reason(name) is not None
            if has_block == has_reason:
                state = "both a block and a reason" if has_block else "neither a block nor a reason"
                raise ValueError(f"metric {name!r} has {state}; expected exactly one (null plus {name}_reason)")
        return self

    def get(self, metric: Metric[BlockT]) -> BlockT | None:
        """The computed block of ``metric`` (None when not applicable), typed by the metric's block."""
        value = self.block(metric.name)
        if value is not None and not isinstance(value, metric.models):
            raise TypeError(f"metrics.json {metric.name}: holds a {type(value).__name__}, not one of its models")
        return value  # checked just above against the metric's own models

    def block(self, name: str) -> Record | None:
        """The computed block of the metric called ``name`` (None when not applicable)."""
        self.REGISTRY.get(name)  # KeyError for a name that is no metric
        value: Record | None = getattr(self, name)
        return value

    def reason(self, name: str) -> str | None:
        """Why the metric called ``name`` is not applicable (None when it was computed)."""
        self.REGISTRY.get(name)
        value: str | None = getattr(self, f"{name}_reason")
        return value


def build_metrics_record(registry: MetricRegistry) -> type[MetricsRecordBase]:
    """The ``metrics.json`` model of ``registry``: two fields per metric, in registry order."""
    fields: dict[str, Any] = {}
    for metric in registry:
        block_type: Any = Union[metric.models]  # noqa: UP007 (a runtime tuple of types)
        fields[metric.name] = (block_type | None, None)
        fields[f"{metric.name}_reason"] = (str | None, None)
    model: type[MetricsRecordBase] = create_model(
        "MetricsRecord", __base__=MetricsRecordBase, __module__=__name__, **fields
    )
    model.REGISTRY = registry
    return model


if TYPE_CHECKING:
    MetricsRecord = MetricsRecordBase
else:
    #: ``metrics.json`` (the project's metrics).
    MetricsRecord = build_metrics_record(metric_registry())
