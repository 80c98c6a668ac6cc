"""The JSON records of a run as typed models: ``result.json``, the bench's ``attempt.json``, and their base.

Why one module: the run-folder writer (:mod:`albot1.runs.folder`), the bench
and the report's table columns all read or write these files. With one typed
definition, a field renamed in a writer breaks a reader's test instead of
turning into an empty table cell. The module sits right below the data
layer (it imports only pydantic, :mod:`albot1.errors` and the shared
wording of validation errors, :mod:`albot1.config.validation`), so the
contract and every layer above may use it. ``metrics.json`` is built on the
same base by the metrics layer: each block is typed in its metric's module
(:mod:`albot1.metrics.measures`) and the record from the metric registry
(:mod:`albot1.metrics.record`). ``docs/metrics.md`` lists the fields of
``metrics.json``; ``docs/architecture.md`` ("Result records") the rules below.

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
  (:class:`albot1.metrics.record.MetricsRecord` enforces "a block or a reason, never both, never
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
from typing import Annotated, Any, ClassVar, Literal, TypeVar, Union, cast, get_args, get_origin

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    SerializerFunctionWrapHandler,
    StringConstraints,
    ValidationError,
    model_serializer,
)

from albot1.config.validation import describe_errors
from albot1.errors import Albot1Error
from albot1.filetypes import not_regular

RecordT = TypeVar("RecordT", bound="Record")
#: A sha256 checksum as the files hold it: 64 lower-case hex digits.
Sha256 = Annotated[str, StringConstraints(pattern=r"^[0-9a-f]{64}$")]


class RecordError(Albot1Error):
    """A result/metrics/attempt record does not fit its model (a file from elsewhere, or a writer's bug)."""


def json_value(value: object) -> Any:
    """``value`` as plain JSON data: numpy scalars/arrays to Python, non-finite floats to None, keys to str.

    Objects with a ``tolist`` method (numpy arrays and scalars) are converted
    through it, so this module needs no numpy import. The plain types are
    tried first by exact type (the same result as the checks below, which an
    ABC's ``isinstance`` makes slow): a run's ``extras.json`` walks ~10^5 values.
    """
    kind = type(value)
    if kind is str or kind is bool or kind is int or value is None:
        return value
    if kind is float:
        return value if math.isfinite(cast(float, value)) else None
    if kind is dict:
        return {str(k): json_value(v) for k, v in cast(dict[Any, Any], value).items()}
    if kind is list:
        return [json_value(v) for v in cast(list[Any], value)]
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


def _not_negative(value: float | None) -> float | None:
    if value is not None and value < 0:
        raise ValueError(f"found {value!r}; expected a number >= 0 (an error, a distance or a time is never negative)")
    return value


def _a_fraction(value: float | None) -> float | None:
    if value is not None and not 0.0 <= value <= 1.0:
        raise ValueError(f"found {value!r}; expected a fraction from 0 to 1")
    return value


#: An error magnitude, distance, duration or size: a negative one is a hand edit or a bug, never a result.
NonNegative = Annotated[float, AfterValidator(_not_negative)]
OptNonNegative = Annotated[float | None, BeforeValidator(_finite_or_none), AfterValidator(_not_negative)]
#: A count or a scan index: a negative one is a hand edit or a bug (json_value has made numpy ints plain ints).
Count = Annotated[int, Field(ge=0)]
#: A share of a whole (precision, coverage, recall).
Fraction = Annotated[float, AfterValidator(_a_fraction)]
OptFraction = Annotated[float | None, BeforeValidator(_finite_or_none), AfterValidator(_a_fraction)]


class Record(BaseModel):
    """Base of every record: unknown keys are errors, values are read-only, NaN is refused."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


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
    problem = not_regular(path)  # a FIFO would block the read, a device never end it
    if problem is not None:
        raise RecordError(f"{path}: {problem}; expected a {model.__name__} file")
    try:
        data = json.loads(path.read_text(encoding="utf-8"), parse_constant=_NonFinite)
    except (OSError, json.JSONDecodeError) as exc:
        raise RecordError(f"{path}: cannot read a {model.__name__}: {exc}") from None
    where = _non_finite_at(data)
    if where is not None:
        field, token = where
        raise RecordError(
            f"{path}: {field or '(top level)'}: found {token}; expected a finite number "
            "(a record's writer stores an undefined number as null)"
        )
    return parse_record(model, data, str(path))


class _NonFinite:
    """``NaN``, ``Infinity`` or ``-Infinity`` as read from a record file (Python's json reads them, JSON has none)."""

    def __init__(self, token: str) -> None:
        self.token = token


def _non_finite_at(data: object, where: str = "") -> tuple[str, str] | None:
    """The dotted field path and token of the first non-finite constant in ``data``, or None.

    The writers never store one (:func:`json_value` makes it null), so it is a hand edit: refused with its
    field, not read as a number or silently as null.
    """
    if isinstance(data, _NonFinite):
        return where, data.token
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, list) else ()
    for key, value in items:
        found = _non_finite_at(value, f"{where}.{key}" if where else str(key))
        if found is not None:
            return found
    return None


def dump_record(record: Record) -> dict[str, Any]:
    """The JSON object of ``record``, in file key order."""
    data: dict[str, Any] = record.model_dump(mode="json")
    return data


# --------------------------------------------------------------------------- result.json


class Timing(OmitsAbsentReasons):
    """``result.json`` ``timing``: per-scan time of ``process`` (ms), seconds, MiB.

    The per-scan statistics are null for a run of no scans, and for a method that does its work in ``finish``
    (a batch program: ``process`` only keeps the frame), where ``per_scan_reason`` says so: its microseconds of
    bookkeeping read as the fastest method of a cost table. ``per_scan_reason`` is written only when set.
    """

    per_scan_ms_median: OptNonNegative
    per_scan_ms_p95: OptNonNegative
    per_scan_ms_mean: OptNonNegative
    finish_s: NonNegative
    total_s: NonNegative
    wall_s: NonNegative
    peak_mb: NonNegative
    #: CPU seconds (user + system, threads and waited children) over the span of ``wall_s``: the cost a shared
    #: machine's load does not inflate; absent in results written before it was recorded
    cpu_s: OptNonNegative = None
    #: seconds before the first scan (the method's warm-up, e.g. compiling kernels), outside the per-scan figures;
    #: absent in results written before it was recorded
    startup_s: OptNonNegative = None
    #: why the per-scan statistics are null although the run has scans (absent otherwise)
    per_scan_reason: str | None = None


class DatasetInfo(Record):
    """``result.json`` ``dataset_info``: where the sequence came from (strings may be empty when unknown)."""

    source: str
    format: str
    odometry_source: str
    reference_source: str
    #: the laser's pose on the robot (x m, y m, yaw rad) the runner applied (albot1.data.transforms.sensor_frame);
    #: absent in results written before it was recorded
    sensor_offset: Annotated[tuple[float, float, float], Field(strict=False)] = (0.0, 0.0, 0.0)
    #: sha256 of every file the sequence was read from, by file name (albot1.data.identity); empty for a
    #: synthetic world (its code version names it) and in results written before it was recorded
    data_sha256: dict[str, Sha256] = {}
    #: the ``[loader]`` table of a registered dataset's manifest (albot1.data.model.SequenceMetadata); empty for
    #: other sources and in results written before it was recorded
    manifest_loader: dict[str, Any] = {}


class ResultRecord(Record):
    """``result.json``: what was run, on what, with which code, and what it cost.

    ``key`` names the run folder; ``dataset`` is the reference the run was
    opened with (so ``albot1 evaluate`` can reopen it); ``config`` is the
    method's resolved config; ``versions`` holds ``code``, ``git``, the
    library versions (null when absent) and, for a plugin method, ``plugin``
    (its distribution and version); ``counters`` holds at least ``views`` and
    ``updates``; ``relations`` is the number of ground-truth relations stored
    beside it (0 when none).
    """

    key: str
    method: str
    dataset: str
    preset: str
    degradation: str
    seed: int
    scans: Count
    config: dict[str, Any]
    versions: dict[str, str | None]
    dataset_info: DatasetInfo
    counters: dict[str, int | float]
    timing: Timing
    map_file: Literal["map.geojson", "map.npz"]
    has_reference: bool
    relations: Count


# --------------------------------------------------------------------------- attempt.json


class AttemptRecord(OmitsAbsentReasons):
    """The bench's ``attempt.json``: wall time of the cell's successful attempt (run + store + evaluation).

    ``elapsed_s`` counts from the moment the cell's process existed; ``launch_s`` is the time spent starting
    it before that, which holds the forkserver's preload for the cells that waited for a server still
    starting (:class:`albot1.bench.limits.ChildExit`); absent in attempts written before it was recorded.
    """

    OMITTED_WHEN_NULL: ClassVar[frozenset[str]] = frozenset({"launch_s"})

    elapsed_s: float
    host: str
    finished: str
    launch_s: OptFloat = None


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
