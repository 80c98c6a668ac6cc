"""Decoded logs cached on disk: each log is parsed once per machine, not once per benchmark cell.

Decoding a raw CARMEN log (text parsing, pose interpolation) costs 0.5-2 s
per log, and every cell of a suite opened its log again. The frames a loader
yields are therefore kept as arrays in one ``.npz`` file per log under
:func:`albot1.settings.decoded_cache_dir` (``ALBOT1_DECODED_CACHE`` redirects it
or, set to ``off``, switches it off), named

    <sha256 of the data file>-<sha256 of loader, options and decoder version>.npz

The first part is the log's content checksum (:mod:`albot1.data.identity`,
itself cached by ``stat``), so an edited log is decoded again; the second
covers the format, every loader option (and the checksum of any option that
names a file) and :func:`decoder_version`, a digest of the loader's source
files and of this module, so a changed loader never reads an old entry.

What is cached is the *raw* decode, frame for frame as the loader yields
them: slices (``[:N:S]``), ``odometry=reference``, ``views=`` and the
runners' odometry degradation act on the frames read back, exactly as on
freshly decoded ones. The frames read back are bit-identical (same dtypes,
values, shared read-only beam-angle arrays and write flags); a test checks
it on real logs.

The cache is never trusted beyond that: an entry that does not load (a
truncated or damaged file: zip CRC or any other zip error, shapes, dtypes), or
whose stored ``key`` is not its file name (an entry of another log or code
version copied or renamed into its place), is ignored, rebuilt and said once
(a warning naming the entry and why); entries are written atomically
(:func:`albot1.atomic.atomic_write`), so two cells decoding one log at once
both write a whole entry and the last rename wins; a folder that cannot be
written means decoding every time, said once per folder and process.
Only loaders that report nothing while they stream are cached (CARMEN
today): a loader that logs warnings during decoding (the ROS bag loader's
dropped scans) would lose them on a cached read.
"""

from __future__ import annotations

import hashlib
import inspect
import io
import json
import logging
import struct
import zipfile
import zlib
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from albot1.atomic import atomic_write
from albot1.data.identity import content_sha256
from albot1.data.model import Frame, Scan, Sequence
from albot1.settings import decoded_cache_dir

log = logging.getLogger(__name__)

#: Bumped by hand when the layout of an entry changes (the loader's own changes are caught by its source digest).
LAYOUT = 2
#: Formats whose decoding is cached (their loaders emit no warning while streaming frames).
CACHED_FORMATS = frozenset(("carmen",))
#: Every array of an entry and its one dtype: an entry holding another (an old layout, a hand-made file) is
#: refused, since frames of another dtype would give a run other numbers than a fresh decode.
_DTYPES = {
    "ranges": np.dtype(np.float64),
    "offsets": np.dtype(np.int64),
    "angles": np.dtype(np.float64),
    "angle_offsets": np.dtype(np.int64),
    "angle_of": np.dtype(np.int64),
    "stamps": np.dtype(np.float64),
    "max_range": np.dtype(np.float64),
    "odometry": np.dtype(np.float64),
    "reference": np.dtype(np.float64),
    "has_reference": np.dtype(np.bool_),
    "writeable": np.dtype(np.bool_),
}
#: What reading a damaged ``.npz`` raises: zipfile alone raises RuntimeError ("encrypted") and
#: NotImplementedError (a compression method) for one flipped header bit, besides the obvious ones.
UNREADABLE = (
    OSError,
    ValueError,
    EOFError,
    KeyError,
    RuntimeError,
    NotImplementedError,
    OverflowError,
    MemoryError,
    struct.error,
    zlib.error,
    zipfile.BadZipFile,
)
_warned_folders: set[Path] = set()


@cache
def decoder_version(loader_module: str) -> str:
    """Digest of the loader package's source files, the loaders' shared ``base.py`` (its pose-gap rule decides
    what a CARMEN load refuses), this module's and :data:`LAYOUT` (16 hex digits)."""
    import importlib

    digest = hashlib.sha256(f"layout {LAYOUT}\n".encode())
    module = importlib.import_module(loader_module)
    folder = Path(inspect.getfile(module)).parent
    # data/loaders/base.py found by path: importing the loaders here would make a cycle between siblings
    shared = [base] if (base := folder.parent / "base.py").is_file() else []
    sources = sorted(folder.glob("*.py")) + shared + [Path(__file__), Path(inspect.getfile(Frame))]
    for source in sources:
        digest.update(source.name.encode() + b"\0" + source.read_bytes())
    return digest.hexdigest()[:16]


def entry_key(path: Path, format_name: str, loader_module: str, options: dict[str, Any]) -> str:
    """``<data sha256>-<digest of format, options and decoder version>``: the entry's file stem."""
    described = {}
    for name, value in sorted(options.items()):
        text = str(value)
        file = Path(text).expanduser() if isinstance(value, str | Path) else None
        if file is not None and _is_file(file):
            text = f"file:{content_sha256(file)}"  # the content of an option's file, not its name
        described[name] = [type(value).__name__, text]
    blob = json.dumps([format_name, decoder_version(loader_module), described], sort_keys=True)
    return f"{content_sha256(path)}-{hashlib.sha256(blob.encode()).hexdigest()[:16]}"


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def cached(sequence: Sequence, path: Path, format_name: str, loader_module: str, options: dict[str, Any]) -> Sequence:
    """``sequence`` whose frames come from the decoded-log cache (decoded and stored on the first read).

    ``sequence`` is returned unchanged when the cache is off or the format is
    not cached. Opening stays lazy: nothing is read before the frames are.
    """
    folder = decoded_cache_dir()
    if folder is None or format_name not in CACHED_FORMATS:
        return sequence
    entry = folder / f"{entry_key(path, format_name, loader_module, options)}.npz"
    held: dict[str, Any] = {}

    def frames() -> Iterator[Frame]:
        if "arrays" not in held:
            arrays, problem = load_entry(entry)
            if problem is not None:
                log.warning("%s: decoded-log cache entry %s; decoding %s again and replacing it", entry, problem, path)
            if arrays is None:
                arrays = encode(sequence.frames())
                if arrays is None:  # frames the layout cannot hold: stream them as decoded, every time
                    return sequence.frames()
                arrays["key"] = np.array(entry.stem)
                _store(entry, arrays, path)
            held["arrays"] = arrays
        return decode(held["arrays"])

    return Sequence(sequence.name, frames, sequence.metadata, sequence.relations, scan_count=sequence.known_scan_count)


def encode(frames: Iterator[Frame]) -> dict[str, np.ndarray] | None:
    """The arrays of an entry from a full pass over ``frames``; None if they do not fit the layout.

    Beam-angle arrays shared between scans (the loaders share one read-only
    array per beam geometry) are stored once and shared again on reading.
    """
    ranges: list[np.ndarray] = []
    angle_sets: list[np.ndarray] = []
    angle_index: dict[int, int] = {}
    angle_of, stamps, max_range, odometry, reference, has_reference = [], [], [], [], [], []
    flags: list[tuple[bool, ...]] = []
    for i, frame in enumerate(frames):
        scan = frame.scan
        if frame.index != i:
            return None
        ranges.append(scan.ranges)
        known = angle_index.get(id(scan.angles))
        if known is None:
            known = angle_index[id(scan.angles)] = len(angle_sets)
            angle_sets.append(scan.angles)  # kept alive: its id stays unique
        angle_of.append(known)
        stamps.append(scan.timestamp)
        max_range.append(scan.max_range)
        odometry.append(frame.odometry)
        has_reference.append(frame.reference is not None)
        reference.append(frame.reference if frame.reference is not None else np.full(3, np.nan))
        flags.append(_flags(frame))
    if not ranges:
        return None
    if len(set(flags)) != 1 or not _uniform([ranges, angle_sets, odometry, reference]):
        return None
    if not all(type(v) is float for v in stamps + max_range):
        return None
    return {
        "ranges": np.concatenate(ranges),
        "offsets": np.cumsum([0] + [len(r) for r in ranges], dtype=np.int64),
        "angles": np.concatenate(angle_sets),
        "angle_offsets": np.cumsum([0] + [len(a) for a in angle_sets], dtype=np.int64),
        "angle_of": np.asarray(angle_of, dtype=np.int64),
        "stamps": np.asarray(stamps, dtype=np.float64),
        "max_range": np.asarray(max_range, dtype=np.float64),
        "odometry": np.stack(odometry),
        "reference": np.stack(reference),
        "has_reference": np.asarray(has_reference, dtype=np.bool_),
        "writeable": np.asarray(flags[0], dtype=np.bool_),
    }


def _flags(frame: Frame) -> tuple[bool, ...]:
    """Write flags of a frame's ranges, angles, odometry and reference (reproduced on reading)."""
    ref = frame.reference
    return (
        bool(frame.scan.ranges.flags.writeable),
        bool(frame.scan.angles.flags.writeable),
        bool(frame.odometry.flags.writeable),
        bool(ref.flags.writeable) if ref is not None else True,
    )


def _uniform(groups: list[list[np.ndarray]]) -> bool:
    """Every array of a group is 1-D float64 (poses of 3 values): what the concatenated layout holds."""
    for group in groups:
        if {(a.dtype, a.ndim) for a in group} != {(np.dtype(np.float64), 1)}:
            return False
    return all(a.shape == (3,) for a in groups[2] + groups[3])


def decode(arrays: dict[str, np.ndarray]) -> Iterator[Frame]:
    """The frames of an entry's arrays, as the loader yielded them."""
    ranges, offsets = arrays["ranges"], arrays["offsets"]
    w_ranges, w_angles, w_odom, w_ref = (bool(v) for v in arrays["writeable"])
    bounds = arrays["angle_offsets"]
    angle_sets = [_flagged(arrays["angles"][a:b].copy(), w_angles) for a, b in zip(bounds[:-1], bounds[1:])]
    odometry, reference, has_reference = arrays["odometry"], arrays["reference"], arrays["has_reference"].tolist()
    cuts, angle_of = offsets.tolist(), arrays["angle_of"].tolist()
    stamps, max_range = arrays["stamps"].tolist(), arrays["max_range"].tolist()
    for i in range(len(cuts) - 1):
        scan = Scan(
            _flagged(ranges[cuts[i] : cuts[i + 1]].copy(), w_ranges), angle_sets[angle_of[i]], stamps[i], max_range[i]
        )
        ref = _flagged(reference[i].copy(), w_ref) if has_reference[i] else None
        yield Frame(i, scan, _flagged(odometry[i].copy(), w_odom), ref)


def _flagged(array: np.ndarray, writeable: bool) -> np.ndarray:
    if not writeable:
        array.setflags(write=False)
    return array


def read_entry(entry: Path) -> dict[str, np.ndarray] | None:
    """The arrays of a cache entry, or None when it is missing, truncated, damaged, inconsistent or another's."""
    return load_entry(entry)[0]


def load_entry(entry: Path) -> tuple[dict[str, np.ndarray] | None, str | None]:
    """``(arrays, None)`` for a usable entry, ``(None, None)`` for none, ``(None, why)`` for one that is unusable.

    An entry is usable when it loads, its stored ``key`` is its file name (the
    name is the sha256 of the log and of the decoder: an entry of another log
    renamed into place must not pass for this one) and its arrays fit together.
    """
    arrays = load_npz(entry)
    if arrays is None or isinstance(arrays, str):
        return None, arrays
    key = arrays.get("key")
    if key is None or key.shape != () or key.dtype.kind != "U" or str(key) != entry.stem:
        found = str(key)[:100] if key is not None and key.shape == () else "none"
        return None, f"holds another key ({found}; expected its own name)"
    if not _consistent(arrays):
        return None, "holds arrays of other dtypes or shapes than the layout's"
    return arrays, None


def load_npz(entry: Path) -> dict[str, np.ndarray] | str | None:
    """Every array of the ``.npz`` file ``entry``; None when there is none; why, when it does not load.

    The one reader of this cache's files and of the reference maps' beside them
    (:mod:`albot1.metrics.reference_map`): whatever a damaged zip raises is a reason to rebuild, never an error.
    """
    try:
        # Opened here, not by np.load: numpy leaves its own handle open when the zip does not parse.
        with entry.open("rb") as handle, np.load(handle, allow_pickle=False) as npz:  # CRCs checked as members are read
            return {name: npz[name] for name in npz.files}
    except (FileNotFoundError, NotADirectoryError):
        return None
    except UNREADABLE as exc:
        said = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)[:120]  # the path is named
        return f"does not load ({type(exc).__name__}: {said})"


def _consistent(arrays: dict[str, np.ndarray]) -> bool:
    """Whether the arrays of an entry have the layout's dtypes and fit together (damage that still unzipped)."""
    if not all(name in arrays and arrays[name].dtype == dtype for name, dtype in _DTYPES.items()):
        return False
    offsets, bounds = arrays["offsets"], arrays["angle_offsets"]
    n = int(offsets.shape[0]) - 1
    shapes_ok = (
        n >= 1
        and offsets.ndim == 1
        and bounds.ndim == 1
        and bounds.shape[0] >= 2
        and int(offsets[0]) == 0
        and int(offsets[-1]) == arrays["ranges"].shape[0]
        and bool(np.all(np.diff(offsets) >= 0))
        and int(bounds[0]) == 0
        and int(bounds[-1]) == arrays["angles"].shape[0]
        and bool(np.all(np.diff(bounds) >= 0))
        and all(arrays[k].shape == (n,) for k in ("angle_of", "stamps", "max_range", "has_reference"))
        and all(arrays[k].shape == (n, 3) for k in ("odometry", "reference"))
        and arrays["writeable"].shape == (4,)
    )
    if not shapes_ok:
        return False
    angle_of = arrays["angle_of"]
    if int(angle_of.min()) < 0 or int(angle_of.max()) >= bounds.shape[0] - 1:
        return False
    beams = np.diff(offsets)
    return bool(np.all(beams == np.diff(bounds)[angle_of]))


def write_entry(entry: Path, arrays: dict[str, np.ndarray]) -> bool:
    """Store ``arrays`` atomically at ``entry``; False (and nothing stored) when the folder cannot be written."""
    return _write(entry, arrays) is None


def _write(entry: Path, arrays: dict[str, np.ndarray]) -> OSError | None:
    """Store ``arrays`` atomically at ``entry``; the error when it cannot be stored."""

    def write(tmp: Path) -> None:
        buffer = io.BytesIO()
        members: dict[str, Any] = dict(arrays)
        np.savez(buffer, **members)
        tmp.write_bytes(buffer.getvalue())

    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(entry, write)
    except OSError as exc:
        return exc
    return None


def _store(entry: Path, arrays: dict[str, np.ndarray], path: Path) -> None:
    """Write an entry; a folder that cannot be written is said once per process (the log is decoded each time)."""
    error = _write(entry, arrays)
    if error is not None and entry.parent not in _warned_folders:
        _warned_folders.add(entry.parent)
        log.warning(
            "%s: cannot store the decoded log (%s); %s is decoded on every read "
            "(point ALBOT1_DECODED_CACHE at a writable folder, or set it to off)",
            entry,
            error.strerror or type(error).__name__,
            path,
        )


def clear(folder: Path | None = None) -> int:
    """Delete every entry of the decoded-log cache (``folder`` or the configured one); the number deleted."""
    target = folder if folder is not None else decoded_cache_dir()
    if target is None or not target.is_dir():
        return 0
    removed = 0
    for entry in target.glob("*.npz"):
        try:
            entry.unlink()
            removed += 1
        except OSError:
            continue
    return removed
