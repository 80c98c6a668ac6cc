"""One entry point from a user's dataset argument to a Sequence.

``ref`` may be an embedded synthetic world name, a registered dataset name
(resolved through the catalog and the dataset settings) or a path to a file
of any known format, optionally followed by loader options and a slice::

    intel-corrected?odometry=laser-pose      loader options (key=value&key=value)
    intel[:1000]   intel[:5000:5]   intel[::2]   the first STOP scans, every STEP-th

Two options apply to every dataset and are handled here, not by a loader
(the inputs of the thesis's experiments; ``docs/datasets.md``, "Reference
options"):

    NAME?odometry=reference     the reference poses as odometry (perfect odometry)
    NAME?views=D_M:A_DEG        keep a scan once the odometry moved D_M metres or turned A_DEG degrees

and, on every source alike (:mod:`albot1.data.attach`; the table of every
option of every format is in ``docs/formats.md``):

    NAME?relations=FILE         a relations file of one's own (replaces the source's)
    NAME?reference=FILE         a reference trajectory of one's own (TUM, KITTI, corrected CARMEN log)
    NAME?reference=FILE&reference_max_dt=S   largest scan-to-pose time gap (default 0.01 s)

The own files are attached first, ``odometry=reference`` is applied next, so ``views`` then spaces the views
by the reference poses; a degradation (applied by the runner) acts on the
kept views' steps.

The whole string names what a run used, so a stored run reopens its data
exactly (``albot1 evaluate`` relies on this).
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path
from typing import Any

from albot1.config.keyvalue import KeyValueError, parse_query
from albot1.config.suggest import did_you_mean
from albot1.data import catalog
from albot1.data.attach import with_reference, with_relations
from albot1.data.degrade import degrade, parse_spec
from albot1.data.errors import DatasetNotFoundError, ReferenceOptionError, SliceError
from albot1.data.filekind import check_input
from albot1.data.finite import checked
from albot1.data.identity import content_sha256
from albot1.data.loaders.base import REFERENCE_KEYWORDS
from albot1.data.loaders.registry import load
from albot1.data.model import Sequence
from albot1.data.synthetic import worlds
from albot1.data.tokens import parse_scalar
from albot1.data.transforms import head, reference_odometry, stride, view_spacing
from albot1.settings import Settings, get_settings

#: ``odometry=reference``: the value that selects the reference poses as odometry on any dataset.
REFERENCE = "reference"
#: Keyword names the opening functions take themselves: as ``?key=value`` they ended in a TypeError traceback
#: ("open_sequence() got multiple values for keyword argument 'settings'"); no loader has such an option.
NOT_LOADER_OPTIONS = ("format_name", "manifest_relations", "path", "ref", "self", "settings")


def open_sequence(
    ref: str | Path, *, settings: Settings | None = None, format_name: str | None = None, **options: Any
) -> Sequence:
    """Open ``ref`` (world name, dataset name or path) as a streamed Sequence."""
    text = str(ref)
    # "NAME[:STOP]" / "NAME[:STOP:STEP]" / "NAME[::STEP]": the first STOP scans, every STEP-th of them
    # (the benchmark suites name their slices of long logs this way, so a run's dataset reopens as run).
    base, stop, step = split_slice(text)
    if base != text:
        sequence = open_sequence(base, settings=settings, format_name=format_name, **options)
        if stop is not None:
            sequence = head(sequence, stop)
        if step is not None:
            sequence = stride(sequence, step)
        return sequence
    name, has_query, query = text.partition("?")
    if has_query and not _exists(text):
        return open_sequence(
            name, settings=settings, format_name=format_name, **{**parse_options(query, text), **options}
        )
    if _own_files(options):
        return _with_own_files(text, settings, format_name, options)
    if options.get("odometry") == REFERENCE or "views" in options:
        return _with_reference_options(text, settings, format_name, options)
    return _open_source(text, settings, format_name, options)


def _open_source(
    text: str,
    settings: Settings | None,
    format_name: str | None,
    options: dict[str, Any],
    *,
    manifest_relations: bool = True,
) -> Sequence:
    """``text`` (a world, a catalog name or a path; no slice, no query) opened with its loader's ``options``.

    ``manifest_relations=False``: a catalog dataset's own relations file is
    left unread, as ``?relations=FILE`` replaces it (:func:`_with_own_files`).
    """
    if text in worlds.WORLDS:
        if "odometry" in options:  # not REFERENCE (handled above): a world's odometry has no other source
            raise DatasetNotFoundError(
                f"{text!r}: odometry={options['odometry']!r}{did_you_mean(str(options['odometry']), [REFERENCE])}; "
                f"a synthetic world takes odometry={REFERENCE} only (its odometry is simulated)"
            )
        return worlds.load_world(text, **options)  # a world's own options (start=, laps=) or SyntheticWorldError
    settings = settings or get_settings()
    _check_option_files(options, text)
    if text in catalog.names():
        if "name" in options:  # a log file's option (the sequence's name); it clashed with open_dataset's own
            raise DatasetNotFoundError(
                f"{text!r}: name={options['name']} names the sequence of a log file given by path; a registered "
                f"dataset keeps its own name ({text})"
            )
        checksums = _checksums(None, options)
        dataset = catalog.open_dataset(text, settings, manifest_relations=manifest_relations, **options)
        return _attach(checked(dataset), checksums)
    path = Path(text).expanduser()
    if _exists(text):
        # The file (or every file of a bag folder) is checked and hashed before a loader opens it: a FIFO
        # among a bag's files would block the loader, and the checksum is cached for every later use.
        check_input(path, "a log file or a ROS2 bag folder", folder_ok=True)
        checksums = _checksums(path, options)
        return _attach(checked(load(path, format_name, **options)), checksums)
    known = catalog.names() + sorted(worlds.WORLDS)
    raise DatasetNotFoundError(
        f"{text!r} is neither a dataset name nor an existing file"
        f"{did_you_mean(text, known)}; `albot1 datasets list` lists all {len(known)} datasets"
    )


def open_as_run(
    ref: str,
    degradation: str = "none",
    seed: int | None = None,
    *,
    settings: Settings | None = None,
    opened: Sequence | None = None,
) -> Sequence:
    """``ref`` opened as a stored run saw it: with the run's degradation and seed (``result.json``).

    The runner degrades after opening (:func:`albot1.runs.execute.run_method`),
    and a degradation may change the scans themselves (``dropout:P`` leaves
    scans out and renumbers the rest), so whatever reopens a run's data
    (evaluation's reference map, the thesis page's replay) reopens it with
    the same SPEC and seed, or it compares the run with other scans. A
    source without a seed (an external trajectory) was not degraded.
    ``opened``: ``ref`` as :func:`open_sequence` opened it moments ago (a
    bench cell's own, undegraded, whose run was just stored), used instead of
    opening the log again: a sequence streams its frames afresh each time, so
    it reads the same scans (docs/benchmarking.md, "Session 24").
    """
    spec = parse_spec(degradation, stored=True)
    sequence = opened if opened is not None else open_sequence(ref, settings=settings)
    return degrade(sequence, spec, seed=0 if seed is None else seed)


def _checksums(path: Path | None, options: dict[str, Any]) -> dict[str, str]:
    """File name -> sha256 of the log at ``path`` and of every loader option naming a file.

    The content a result is computed from (``relations=``, ``reference=``
    files included; :mod:`albot1.data.identity`, cached). A catalog
    dataset's own files are verified and recorded by the catalog.
    """
    files = [path] if path is not None else []
    files += [Path(v).expanduser() for k, v in options.items() if _names_path(k, v) and _is_file(str(v))]
    return {f.name: content_sha256(f) for f in files}


def _attach(sequence: Sequence, checksums: dict[str, str]) -> Sequence:
    """``sequence`` with ``checksums`` added to its metadata's."""
    if not checksums:
        return sequence
    return sequence.with_metadata(replace(sequence.metadata, checksums={**sequence.metadata.checksums, **checksums}))


def _check_option_files(options: dict[str, Any], ref: str) -> None:
    """DataError for a loader option naming a FIFO, device, socket, pseudo-file or folder (``relations=/dev/zero``).

    Checked by ``stat`` before any loader opens it, as a log is
    (:func:`albot1.data.filekind.check_input`): reading one would hang or never end.
    """
    for key, value in options.items():
        if _names_path(key, value) and _exists(str(value)):
            check_input(Path(value).expanduser(), f"a regular file for the option {key}= of {ref!r}")


def _names_path(key: str, value: object) -> bool:
    """Whether a loader option's value is meant as a path (not a word such as ``odom`` that a folder may share).

    A value with a folder separator, a leading ``~`` or a file suffix, or any
    value of ``relations=``.
    """
    if isinstance(value, Path):
        return True
    if not isinstance(value, str):
        return False
    return key == "relations" or "/" in value or value.startswith("~") or bool(Path(value).suffix)


def _is_file(text: str) -> bool:
    try:
        return Path(text).expanduser().is_file()
    except (OSError, ValueError):
        return False


def _exists(text: str) -> bool:
    """Whether ``text`` names an existing path; False for strings no file system accepts (too long, NUL)."""
    try:
        return Path(text).expanduser().exists()
    except (OSError, ValueError):
        return False


#: ``REF[BODY]``: a reference followed by a slice (unless the whole text names an existing path).
_SLICED = re.compile(r"(?P<ref>.+)\[(?P<body>[^\[\]]*)\]")
#: ``NAME[:400]?odometry=laser-pose``: slices written before the loader options instead of after them
_SLICED_BEFORE_QUERY = re.compile(
    r"(?P<name>[^?\[\]]+)(?P<slices>(?:\[[^\[\]?]*\])+)\?(?P<query>[^?\[\]]+)(?P<after>(?:\[[^\[\]?]*\])*)"
)


def split_slice(ref: str) -> tuple[str, int | None, int | None]:
    """``"intel[:300][::2]"`` -> ``("intel", 300, 2)``: the reference under its trailing slices, and the STOP
    and STEP of the one slice they select together (None = not given).

    The one reading of a reference's slices: :func:`open_sequence` opens the reference under them and keeps
    those scans, and the bench finds a sliced dataset's catalog entry by it (``intel[:50]`` of a log that is
    not downloaded is skipped like ``intel``). A text that names an existing path is not sliced. Slices
    apply left to right: a later ``[:B:T]`` keeps the first B of what the earlier ``[:A:S]`` kept (the first
    ``min(A, B*S)`` scans of the log) and every T-th of those (every ``S*T``-th scan of the log). SliceError
    for a slice :func:`parse_slice` refuses.
    """
    slices: list[tuple[str, str]] = []  # (body, the reference it ends), outermost first
    text = ref
    before = _SLICED_BEFORE_QUERY.fullmatch(ref)
    if before is not None and not _exists(ref):
        # The same scans as NAME?QUERY[...]: read so, so both spellings are one run key (they were two) and the
        # canonical spelling puts the slices last. Errors still quote the reference as written.
        text = f"{before['name']}?{before['query']}{before['slices']}{before['after']}"
        while (sliced := _SLICED.fullmatch(text)) is not None:
            slices.append((sliced["body"], ref))
            text = sliced["ref"]
    while (sliced := _SLICED.fullmatch(text)) is not None and not _exists(text):
        slices.append((sliced["body"], text))
        text = sliced["ref"]
    stop: int | None = None
    step = 1
    for body, whole in reversed(slices):
        outer_stop, outer_step = parse_slice(body, whole)
        if outer_stop is not None:
            stop = outer_stop * step if stop is None else min(stop, outer_stop * step)
        step *= outer_step or 1
    return text, stop, step if step != 1 else None


def slice_reference(ref: str, stop: int | None, step: int | None) -> str:
    """The one spelling of ``ref`` sliced: ``intel[:300]``, ``intel[::2]``, ``intel[:300:2]``, or ``ref`` itself
    for every scan (no STOP, STEP 1).

    A slice names part of a run's identity (the bench's run key and run folder), so every spelling of the
    same scans (``intel[:300:1]``, ``intel[0:300]``, ``intel[:0300]``, ``intel[:600][:300]``, ``intel`` with
    ``limit = 300``) is written this one way: :func:`canonical_reference`.
    """
    step = None if step == 1 else step
    if stop is None and step is None:
        return ref
    return f"{ref}[:{'' if stop is None else stop}{'' if step is None else f':{step}'}]"


def canonical_reference(ref: str) -> str:
    """``ref`` with its loader options and trailing slices in their one spelling (:func:`canonical_query`,
    :func:`split_slice`, :func:`slice_reference`)."""
    text, stop, step = split_slice(ref)
    return slice_reference(canonical_query(text), stop, step)


def canonical_query(text: str) -> str:
    """``NAME?b=2&a=1`` -> ``NAME?a=1&b=2``: the loader options of a reference (no slice) in their one spelling.

    The options are a set (:func:`open_sequence` applies them in its own order, whatever order they are
    written in), so ``?odometry=reference&views=1:10`` and ``?views=1:10&odometry=reference``, ``NAME?`` and
    ``NAME``, ``a = 1`` and ``a=1`` open the same scans and are one run key and one table row: keys sorted,
    spaces around keys and values and empty items dropped, values otherwise as written. A text naming an
    existing path, or whose options do not parse (opening it says why), is returned as it is.
    """
    name, has_query, query = text.partition("?")
    if not has_query or _exists(text):
        return text
    try:
        pairs = parse_query(query, what="loader option")
    except KeyValueError:
        return text
    return name + ("?" + "&".join(f"{key}={pairs[key]}" for key in sorted(pairs)) if pairs else "")


def parse_slice(body: str, ref: str) -> tuple[int | None, int | None]:
    """``":100:5"`` -> ``(100, 5)``: the STOP and STEP of a reference's ``[:STOP:STEP]`` (None = not given).

    Only prefixes and strides exist (a run must reopen exactly the scans it
    used); both must be positive integers. Python's ``[0:STOP]`` is
    accepted as the same prefix (:func:`slice_reference` spells it
    ``[:STOP]``). Anything else is a SliceError naming the reference.
    """
    forms = "[:STOP], [:STOP:STEP] or [::STEP] with positive integers (the first STOP scans, every STEP-th of them)"
    found = re.fullmatch(r"(?P<start>[0-9]*):(?P<stop>[0-9]*)(?::(?P<step>[0-9]*))?", body)
    if found is None or len(body) > 40:
        raise SliceError(f"{ref!r}: slice [{body[:40]}] is not understood; expected {forms}")
    if found["start"] and int(found["start"]) != 0:
        raise SliceError(
            f"{ref!r}: slice START is {int(found['start'])}, but only prefixes exist (a START, if given, is 0); "
            f"expected {forms}"
        )
    stop = int(found["stop"]) if found["stop"] else None
    step = int(found["step"]) if found["step"] else None
    for what, value in (("STOP", stop), ("STEP", step)):
        if value is not None and value < 1:
            raise SliceError(f"{ref!r}: slice {what} is {value}, expected a positive integer; use {forms}")
    return stop, step


def parse_options(query: str, ref: str) -> dict[str, Any]:
    """``"a=1&b=x"`` -> ``{"a": 1, "b": "x"}`` (numbers become int/float).

    The split is :func:`albot1.config.keyvalue.parse_query`, the project's one ``KEY=VALUE`` parser.
    """
    try:
        pairs = parse_query(query, what="loader option")
    except KeyValueError as exc:
        raise DatasetNotFoundError(f"{ref!r}: {exc}") from None
    taken = [key for key in pairs if key in NOT_LOADER_OPTIONS]
    if taken:
        raise DatasetNotFoundError(
            f"{ref!r}: loader option {taken[0]!r} is not an option of any loader (a name the opening code keeps "
            "for itself); expected the options of the dataset's loader (docs/formats.md, docs/datasets.md)"
        )
    return {key: parse_scalar(value) for key, value in pairs.items()}


def _with_reference_options(
    text: str, settings: Settings | None, format_name: str | None, options: dict[str, Any]
) -> Sequence:
    """Open ``text`` without the reference options, then apply ``odometry=reference`` and ``views``."""
    rest = dict(options)
    use_reference = rest.get("odometry") == REFERENCE
    if use_reference:
        del rest["odometry"]
    views = rest.pop("views", None)
    sequence = open_sequence(text, settings=settings, format_name=format_name, **rest)
    return _apply_reference_options(
        sequence,
        text,
        {**({"odometry": REFERENCE} if use_reference else {}), **({"views": views} if views is not None else {})},
    )


def _apply_reference_options(sequence: Sequence, text: str, options: dict[str, Any]) -> Sequence:
    """``odometry=reference`` then ``views=D_M:A_DEG`` on an opened sequence."""
    use_reference = options.get("odometry") == REFERENCE
    views = options.get("views")
    if use_reference:
        first = next(iter(sequence), None)
        if first is not None and first.reference is None:
            raise ReferenceOptionError(f"{text!r}: odometry=reference, but the dataset has no reference poses")
        sequence = reference_odometry(sequence)
    if views is not None:
        distance_m, angle_deg = parse_views(views, text)
        sequence = view_spacing(sequence, distance_m, angle_deg)
    return sequence


def _own_files(options: dict[str, Any]) -> bool:
    """Whether ``options`` name a relations or reference file (not a CARMEN ``reference`` keyword)."""
    reference = options.get("reference")
    return (
        "relations" in options
        or "reference_max_dt" in options
        or (reference is not None and str(reference) not in REFERENCE_KEYWORDS)
    )


def _with_own_files(text: str, settings: Settings | None, format_name: str | None, options: dict[str, Any]) -> Sequence:
    """Open ``text`` with the other options, then attach ``relations=FILE`` and ``reference=FILE``."""
    rest = dict(options)
    relations = rest.pop("relations", None)
    repeats = rest.pop("relations_repeats", None) if relations is not None else None
    max_dt = rest.pop("reference_max_dt", None)
    reference = rest.pop("reference", None) if str(rest.get("reference")) not in REFERENCE_KEYWORDS else None
    if max_dt is not None and reference is None:
        raise ReferenceOptionError(f"{text!r}: reference_max_dt goes with reference=FILE, which is not given")
    use_reference = rest.get("odometry") == REFERENCE
    views = rest.pop("views", None)
    if use_reference:
        del rest["odometry"]
    own = {key: value for key, value in (("relations", relations), ("reference", reference)) if value is not None}
    _check_option_files(own, text)  # a FIFO or device is refused before anything reads it
    # the source's own relations are not read when a file of one's own replaces them: neither its warnings
    # (repeated lines) nor its checksum (in the run's key) belong to what the run is scored on
    sequence = _open_source(text, settings, format_name, rest, manifest_relations=relations is None)
    if relations is not None:
        sequence = with_relations(sequence, relations, text, repeats)
    if reference is not None:
        sequence = with_reference(sequence, reference, text, max_dt)
    sequence = _attach(sequence, _checksums(None, own))
    after: dict[str, Any] = {"odometry": REFERENCE} if use_reference else {}
    if views is not None:
        after["views"] = views
    return _apply_reference_options(sequence, text, after) if after else sequence


def parse_views(value: Any, ref: str) -> tuple[float, float]:
    """``"1:10"`` -> ``(1.0, 10.0)``: the ``views=D_M:A_DEG`` option (metres, degrees, both positive)."""
    parts = str(value).split(":")
    try:
        distance_m, angle_deg = (float(p) for p in parts) if len(parts) == 2 else (math.nan, math.nan)
    except ValueError:
        distance_m = angle_deg = math.nan
    if not (math.isfinite(distance_m) and distance_m > 0 and math.isfinite(angle_deg) and angle_deg > 0):
        raise ReferenceOptionError(
            f"{ref!r}: views={value}; expected views=D_M:A_DEG with a positive distance in metres and angle in "
            f"degrees, e.g. views=1:10"
        )
    return distance_m, angle_deg
