"""The JSON records of a run as typed models: ``result.json``, ``metrics.json`` and the bench's ``attempt.json``.

Why one module: the run-folder writer (:mod:`albot1.runs.folder`), ``albot1
evaluate`` (:mod:`albot1.runs.evaluate`), the CLI's headlines and the
report's table columns all read or write these files. With one typed
definition, a field renamed in a writer breaks a reader's test instead of
turning into an empty table cell. The module sits right below the data
layer (it imports only pydantic, :mod:`albot1.errors` and the shared
wording of validation errors, :mod:`albot1.config.validation`), so the
contract and every layer above may use it. ``docs/metrics.md`` lists the
fields of ``metrics.json``; ``docs/architecture.md`` ("Result records")
the rules below.

Conventions the models encode:

* **Field order is key order.** The files are written from
  ``model_dump()``, which follows the declaration order, so the files keep
  the key order they always had.
* **Values are JSON values.** :func:`json_value` turns numpy scalars and
  arrays into Python ones and every non-finite float into ``None`` *before*
  validation, so a model holds exactly what its file holds. Hence every
  statistic that can be undefined (an empty sample, no pair of scans) is
  ``float | None``; a field typed ``float`` rejects NaN.
* **Not applicable is not a number.** In ``metrics.json`` a metric that
  cannot be computed is ``null`` and ``<metric>_reason`` beside it says
  why; a computed metric has no ``_reason`` key at all
  (:class:`MetricsRecord` enforces "a block or a reason, never both, never
  neither"). Inside a block, an undefined statistic is ``null`` next to a
  count that explains it (``n: 0``, ``pairs: 0``, ``bearing_undefined``).
* **Closed to typos, open where methods differ.** Every model forbids
  unknown keys; ``config``, ``counters`` and ``versions`` are dictionaries
  because each method has its own.
"""

from __future__ import annotations

import json
import math
import types
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal, TypeAlias, TypeVar, Union, get_args, get_origin

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    SerializerFunctionWrapHandler,
    ValidationError,
    model_serializer,
    model_validator,
)

from albot1.config.validation import describe_errors
from albot1.errors import Albot1Error

RecordT = TypeVar("RecordT", bound="Record")


class RecordError(Albot1Error):
    """A result/metrics/attempt record does not fit its model (a file from elsewhere, or a writer's bug)."""


def json_value(value: object) -> Any:
    """``value`` as plain JSON data: numpy scalars/arrays to Python, non-finite floats to None, keys to str.

    Objects with a ``tolist`` method (numpy arrays and scalars) are converted
    through it, so this module needs no numpy import.
    """
    if isinstance(value, Mapping):
        return {str(k): json_value(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_value(v) for v in value]
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, float):  # numpy's float64 included (a float subclass)
        return float(value) if math.isfinite(value) else None
    if isinstance(value, int):
        return int(value)
    tolist = getattr(value, "tolist", None)
    if callable(tolist):  # numpy scalar or array
        return json_value(tolist())
    return value


def _finite_or_none(value: object) -> object:
    return None if isinstance(value, float) and not math.isfinite(value) else value


#: A number that may be undefined (JSON ``null``), e.g. the mean of an empty sample.
OptFloat = Annotated[float | None, BeforeValidator(_finite_or_none)]
Alignment = Literal["none", "first", "rigid"]
MetricName = Literal[
    "ate", "ate_windows", "rpe", "drift", "loop_gap", "orientation", "relations", "map_shape", "updates", "cost"
]
#: The metrics of ``metrics.json``, in file order.
METRIC_NAMES: tuple[MetricName, ...] = get_args(MetricName)
#: The ``missing`` note of ``metrics.json``: the not-applicable convention in words.
MISSING_NOTE = "a metric that cannot be computed is null and '<metric>_reason' beside it says why"


class Record(BaseModel):
    """Base of every record: unknown keys are errors, values are read-only, NaN is refused."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class OmitsAbsentReasons(Record):
    """A record whose ``<name>_reason`` keys (and :attr:`OMITTED_WHEN_NULL` keys) are written only when set.

    So a file never holds ``"x_reason": null``, and an optional block that most
    files lack (``trajectory`` of ``metrics.json``) does not appear in them as null.
    """

    OMITTED_WHEN_NULL: ClassVar[frozenset[str]] = frozenset()

    @model_serializer(mode="wrap")
    def _omit_absent_reasons(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        data: dict[str, Any] = handler(self)
        omitted = self.OMITTED_WHEN_NULL
        return {k: v for k, v in data.items() if not ((k.endswith("_reason") or k in omitted) and v is None)}


def parse_record(model: type[RecordT], data: object, source: str) -> RecordT:
    """``model`` validated from ``data`` (made JSON-like first); RecordError naming ``source`` and the field."""
    try:
        return model.model_validate(json_value(data))
    except ValidationError as exc:
        raise RecordError(f"{source}: not a valid {model.__name__}: {describe_errors(exc)}") from None


def read_record(model: type[RecordT], path: Path) -> RecordT:
    """Read and validate one record file; RecordError (one line) when it is unreadable or does not fit."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise RecordError(f"{path}: cannot read a {model.__name__}: {exc}") from None
    return parse_record(model, data, str(path))


def dump_record(record: Record) -> dict[str, Any]:
    """The JSON object of ``record``, in file key order."""
    data: dict[str, Any] = record.model_dump(mode="json")
    return data


# --------------------------------------------------------------------------- result.json


class Timing(Record):
    """``result.json`` ``timing``: per-scan time of ``process`` (ms; null for a run of no scans), seconds, MiB."""

    per_scan_ms_median: OptFloat
    per_scan_ms_p95: OptFloat
    per_scan_ms_mean: OptFloat
    finish_s: float
    total_s: float
    wall_s: float
    peak_mb: float
    #: CPU seconds (user + system, threads and waited children) over the span of ``wall_s``: the cost a shared
    #: machine's load does not inflate; absent in results written before it was recorded
    cpu_s: OptFloat = None
    #: seconds before the first scan (the method's warm-up, e.g. compiling kernels), outside the per-scan figures;
    #: absent in results written before it was recorded
    startup_s: OptFloat = None


class DatasetInfo(Record):
    """``result.json`` ``dataset_info``: where the sequence came from (strings may be empty when unknown)."""

    source: str
    format: str
    odometry_source: str
    reference_source: str
    #: the laser's pose on the robot (x m, y m, yaw rad) the runner applied (albot1.data.transforms.sensor_frame);
    #: absent in results written before it was recorded
    sensor_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)


class ResultRecord(Record):
    """``result.json``: what was run, on what, with which code, and what it cost.

    ``key`` names the run folder; ``dataset`` is the reference the run was
    opened with (so ``albot1 evaluate`` can reopen it); ``config`` is the
    method's resolved config; ``versions`` holds ``code``, ``git`` and the
    library versions (null when absent); ``counters`` holds at least
    ``views`` and ``updates``; ``relations`` is the number of ground-truth
    relations stored beside it (0 when none).
    """

    key: str
    method: str
    dataset: str
    preset: str
    degradation: str
    seed: int
    scans: int
    config: dict[str, Any]
    versions: dict[str, str | None]
    dataset_info: DatasetInfo
    counters: dict[str, int | float]
    timing: Timing
    map_file: Literal["map.geojson", "map.npz"]
    has_reference: bool
    relations: int


# --------------------------------------------------------------------------- attempt.json


class AttemptRecord(Record):
    """The bench's ``attempt.json``: wall time of the cell's successful attempt (run + store + evaluation)."""

    elapsed_s: float
    host: str
    finished: str


# --------------------------------------------------------------------------- metrics.json blocks


class Stats(Record):
    """The shared summary of a sample (:func:`albot1.metrics.stats.summarize`); null statistics when ``n`` is 0."""

    mean: OptFloat
    std: OptFloat
    median: OptFloat
    min: OptFloat
    max: OptFloat
    rmse: OptFloat
    n: int
    std_ddof: int


class RotationStats(Record):
    """:class:`Stats` of a heading error with the unit in the key (``_deg``)."""

    mean_deg: OptFloat
    std_deg: OptFloat
    median_deg: OptFloat
    min_deg: OptFloat
    max_deg: OptFloat
    rmse_deg: OptFloat
    n: int
    std_ddof: int


class AlignmentTransform(Record):
    """The rigid motion an alignment applied to the estimate (m, deg)."""

    method: Alignment
    x_m: float
    y_m: float
    theta_deg: float


class AlignmentSummary(Record):
    """ATE under another alignment, for comparison."""

    rmse_m: float
    mean_m: float
    max_m: float


class AteBlock(Record):
    """``ate``: position error after ``alignment`` (m, population std), heading error under ``rotation``."""

    alignment: Alignment
    units: dict[str, str]
    mean_m: float
    std_m: float
    median_m: float
    min_m: float
    max_m: float
    rmse_m: float
    n: int
    std_ddof: int
    rotation: RotationStats
    alignment_transform: AlignmentTransform
    other_alignments: dict[str, AlignmentSummary]


class WindowStats(Record):
    """:class:`Stats` of the windows' RMSE with the unit in the key (``_m``)."""

    mean_m: float
    std_m: float
    median_m: float
    min_m: float
    max_m: float
    rmse_m: float
    n: int
    std_ddof: int


class AteWindow(Record):
    """One window of ``ate_windows``: its scans (inclusive) and its ATE."""

    first_scan: int
    last_scan: int
    rmse_m: float
    max_m: float


class AteWindowsBlock(Record):
    """``ate_windows``: ATE of consecutive windows of ``window_m`` reference travel, each aligned on its own."""

    alignment: str
    window_m: float
    windows: int
    uncovered_m: float
    units: dict[str, str]
    mean_rmse_m: float
    window_rmse: WindowStats
    per_window: list[AteWindow]


class RpeEntry(Record):
    """One RPE step: ``delta`` frames (an integer) or metres of reference travel."""

    delta: int | float
    delta_unit: Literal["frames", "m"]
    pairs: int
    translation_m: Stats
    rotation_deg: Stats


class RpeBlock(Record):
    """``rpe``: the first step's numbers at the top level, every step under ``deltas``."""

    alignment: str
    pairs_from: str
    units: dict[str, str]
    delta: int | float
    delta_unit: Literal["frames", "m"]
    pairs: int
    translation_m: Stats
    rotation_deg: Stats
    deltas: list[RpeEntry]


class DriftEntry(Record):
    """``drift.sweep`` entry: errors of every segment of ``length_m`` reference travel."""

    length_m: float
    pairs: int
    translation_m: Stats
    rotation_deg: Stats


class DriftAt10m(Record):
    """``drift.at_10m``: mean errors of the 10 m segments (the headline)."""

    translation_m: float
    rotation_deg: float
    pairs: int


class DriftBlock(OmitsAbsentReasons):
    """``drift``: relative error per travelled distance over every start point.

    ``at_10m`` is null with ``at_10m_reason`` when the route has no 10 m segment.
    """

    alignment: str
    pairs_from: str
    start_spacing_m: float
    route_m: float
    units: dict[str, str]
    sweep: list[DriftEntry]
    lengths_beyond_route_m: list[float]
    at_10m: DriftAt10m | None
    at_10m_reason: str | None = None

    @model_validator(mode="after")
    def _value_or_reason(self) -> DriftBlock:
        if (self.at_10m is None) == (self.at_10m_reason is None):
            raise ValueError("at_10m: expected either the 10 m means or at_10m_reason, exactly one")
        return self


class RouteGap(Record):
    """``loop_gap.route``: start-to-end error (m, deg)."""

    estimated_offset_m: float
    reference_offset_m: float
    reference: str
    gap_m: float
    heading_gap_deg: float


class WorstPair(Record):
    """The revisit pair with the largest gap."""

    scans: list[int]
    gap_m: float


class LoopGapBlock(Record):
    """``loop_gap`` with reference poses: the route gap and every revisit pair.

    With ``pairs: 0`` the pair statistics and ``worst_pair`` are null.
    """

    units: dict[str, str]
    alignment: str
    route: RouteGap
    radius_m: float
    min_dt_s: float
    min_travel_m: float
    pairs: int
    translation_m: Stats | None
    rotation_deg: Stats | None
    worst_pair: WorstPair | None


class ClosedRouteGapBlock(Record):
    """``loop_gap`` without reference poses on a route declared closed: the route gap only.

    Revisit pairs need reference positions, so ``pairs`` is null and
    ``pairs_reason`` says why.
    """

    units: dict[str, str]
    alignment: str
    route: RouteGap
    pairs: None
    pairs_reason: str


class OrientationRow(Record):
    """One stop point of the thesis's Table 3.1 (deg, m); the bearing error is null near the start."""

    scan: int
    timestamp: OptFloat
    travel_m: float
    estimate_bearing_deg: float
    estimate_distance_m: float
    reference_bearing_deg: float
    reference_distance_m: float
    bearing_error_deg: OptFloat
    distance_error_m: float


class OrientationBlock(Record):
    """``orientation``: Table 3.1 rows and mean/max absolute differences (null when no row defines them)."""

    alignment: str
    units: dict[str, str]
    every_m: float
    min_distance_m: float
    stops: int
    bearing_undefined: int
    bearing_abs_error_mean_deg: OptFloat
    bearing_abs_error_max_deg: OptFloat
    distance_abs_error_mean_m: OptFloat
    distance_abs_error_max_m: OptFloat
    rows: list[OrientationRow]


class RelationLoops(Record):
    """``relations.loops``: the same statistics over the relations spanning more than ``min_dt_s``."""

    min_dt_s: float
    translation_m: Stats
    rotation_deg: Stats
    translation_squared_m2: Stats
    rotation_squared_deg2: Stats


class RelationsBlock(Record):
    """``relations``: the Kuemmerle et al. (2009) metric (sample std), with how many relations the run covered.

    ``relations_total`` counts the dataset's relations, ``relations_used`` those scored and
    ``relations_outside_run`` those left out because an end names a scan the run did not see (a slice of
    the log; :func:`albot1.data.relations.relations_in_run`), so a slice never drops relations silently.
    """

    alignment: str
    error: str
    std_ddof: int
    relations_total: int
    relations_used: int
    relations_outside_run: int
    max_time_gap_s: float
    translation_m: Stats
    rotation_deg: Stats
    translation_squared_m2: Stats
    rotation_squared_deg2: Stats
    loops: RelationLoops


class MapShapeBlock(Record):
    """``map_shape``: agreement of the map with the reference map (fractions, m)."""

    units: dict[str, str]
    alignment: str
    alignment_transform: AlignmentTransform
    reference_map: str
    tolerance_m: float
    voxel_m: float
    map_points: int
    reference_points: int
    precision: float
    coverage: float
    map_to_reference_mean_m: float
    map_to_reference_median_m: float
    reference_to_map_mean_m: float
    reference_to_map_median_m: float


class UpdatesBlock(Record):
    """``updates``: views, updates, their ratio (null for no views) and every other counter of the method."""

    units: str
    views: int | float
    updates: int | float
    updates_per_view: OptFloat
    counters: dict[str, int | float]


class CostByPosition(Record):
    """``cost.by_position``: the median per-scan time in each tenth of the sequence."""

    scan_centres: list[float]
    per_scan_ms_median: list[float]


class CostBlock(Record):
    """``cost``: per-scan time (ms), totals (s), peak memory (MiB) and growth with position."""

    units: dict[str, str]
    scans: int
    per_scan_ms_median: float
    per_scan_ms_p95: float
    per_scan_ms_mean: float
    per_scan_ms_max: float
    process_total_s: float
    total_s: OptFloat
    finish_s: OptFloat
    peak_mb: OptFloat
    by_position: CostByPosition
    growth_slope_ms_per_1000_scans: OptFloat
    last_over_first_decile: OptFloat


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
    scans: int
    has_reference: bool


class TrajectorySource(Record):
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
    poses: int
    matched: int
    unmatched: int
    duplicates: int
    max_dt_s: float | None
    versions: dict[str, str | None]


#: Any computed block of ``metrics.json``.
MetricBlock: TypeAlias = (
    AteBlock
    | AteWindowsBlock
    | RpeBlock
    | DriftBlock
    | LoopGapBlock
    | ClosedRouteGapBlock
    | OrientationBlock
    | RelationsBlock
    | MapShapeBlock
    | UpdatesBlock
    | CostBlock
)


class MetricsRecord(OmitsAbsentReasons):
    """``metrics.json``: every metric of a run, each a block or null with ``<metric>_reason``.

    ``trajectory`` describes the scored file of an external trajectory and is
    absent from a run folder's metrics.
    """

    OMITTED_WHEN_NULL: ClassVar[frozenset[str]] = frozenset({"trajectory"})

    run: RunHeader
    trajectory: TrajectorySource | None = None
    missing: str = MISSING_NOTE
    ate: AteBlock | None = None
    ate_reason: str | None = None
    ate_windows: AteWindowsBlock | None = None
    ate_windows_reason: str | None = None
    rpe: RpeBlock | None = None
    rpe_reason: str | None = None
    drift: DriftBlock | None = None
    drift_reason: str | None = None
    loop_gap: LoopGapBlock | ClosedRouteGapBlock | None = None
    loop_gap_reason: str | None = None
    orientation: OrientationBlock | None = None
    orientation_reason: str | None = None
    relations: RelationsBlock | None = None
    relations_reason: str | None = None
    map_shape: MapShapeBlock | None = None
    map_shape_reason: str | None = None
    updates: UpdatesBlock | None = None
    updates_reason: str | None = None
    cost: CostBlock | None = None
    cost_reason: str | None = None

    @model_validator(mode="after")
    def _block_or_reason(self) -> MetricsRecord:
        for name in METRIC_NAMES:
            has_block, has_reason = self.block(name) is not None, self.reason(name) is not None
            if has_block == has_reason:
                state = "both a block and a reason" if has_block else "neither a block nor a reason"
                raise ValueError(f"metric {name!r} has {state}; expected exactly one (null plus {name}_reason)")
        return self

    def block(self, name: MetricName) -> MetricBlock | None:
        """The computed block of metric ``name`` (None when not applicable)."""
        value: MetricBlock | None = getattr(self, name)
        return value

    def reason(self, name: MetricName) -> str | None:
        """Why metric ``name`` is not applicable (None when it was computed)."""
        value: str | None = getattr(self, f"{name}_reason")
        return value


# --------------------------------------------------------------------------- dotted paths (report columns)


def _members(annotation: object) -> list[object]:
    """The alternatives of a type annotation: Optional/Union and Annotated unwrapped, None left out."""
    origin = get_origin(annotation)
    if origin is Annotated:
        return _members(get_args(annotation)[0])
    if origin is Union or origin is types.UnionType:
        return [m for arg in get_args(annotation) for m in _members(arg)]
    return [] if annotation is type(None) else [annotation]


def check_number_path(model: type[BaseModel], path: str) -> None:
    """Raise KeyError unless ``path`` (``"a.b.c"``) leads through ``model`` to a numeric field.

    Nested models and their Optional/Union alternatives are followed (a path
    valid in one alternative is valid: the other gives an empty value); under
    a ``dict[str, V]`` field any key is accepted (method counters differ by
    method), and the path continues in ``V``.
    """
    parts = path.split(".")
    candidates: list[object] = [model]
    for depth, part in enumerate(parts):
        following: list[object] = []
        for candidate in candidates:
            for member in _members(candidate):
                if isinstance(member, type) and issubclass(member, BaseModel):
                    field = member.model_fields.get(part)
                    if field is not None:
                        following.append(field.annotation)
                elif get_origin(member) is dict:
                    following.append(get_args(member)[1])
        if not following:
            raise KeyError(f"{model.__name__} has no field {'.'.join(parts[: depth + 1])!r} (column path {path!r})")
        candidates = following
    leaves = [m for c in candidates for m in _members(c)]
    if not leaves or any(leaf not in (int, float) for leaf in leaves):
        names = ", ".join(getattr(leaf, "__name__", str(leaf)) for leaf in leaves) or "None"
        raise KeyError(f"{model.__name__}.{path} is {names}, not a number (column path {path!r})")


def number_at(record: BaseModel | Mapping[str, Any] | None, path: str) -> float | None:
    """The number at ``path`` in ``record`` as a float; None when a step is null or absent, or not a number."""
    current: object = record
    for part in path.split("."):
        if isinstance(current, BaseModel):
            current = getattr(current, part, None)
        elif isinstance(current, Mapping):
            current = current.get(part)
        else:
            return None
    if isinstance(current, bool) or not isinstance(current, (int, float)):
        return None
    return float(current)
