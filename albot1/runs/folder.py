"""The run-folder contract (``docs/architecture.md``, "Contracts").

One folder per run, named by a content hash of (dataset, method, config,
degradation, seed, code and library versions, data; :func:`run_key`)::

    trajectory.tum   estimated pose per scan (scan timestamps)
    odometry.tum     the odometry the method was given (after degradation)
    reference.tum    reference poses, when the dataset has them
    relations.txt    ground-truth relations, when the dataset has them
    result.json      method, dataset, config, versions, counters, timing (albot1.records.ResultRecord)
    map.geojson      the map, every method: line surfaces (Albot1) or points (baselines); runs.map_files
    map.npz          a point map's points again (float32), the file its result.json names
    extras.json      method-specific records (update trace, ...)
    <extra files>    a mapper's own files (``MapperOutput.files``: places.json, places.graphml, ...)
    preview.png      the map with the trajectory (drawn by the caller's renderer, if given)
    DONE             written last, by atomic rename: the run is complete

Every file is written to a temporary name and renamed, so a killed process
leaves either a complete file or none; a folder without DONE is incomplete
and is recomputed. The temporary files a killed writer leaves are removed
when the folder is written again, so a completed folder holds none.
"""

from __future__ import annotations

import hashlib
import json
import os
import zipfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.atomic import atomic_write, remove_temporaries
from albot1.contract import MapData, RunResult
from albot1.data.model import Relations
from albot1.data.relations import read_relations, write_relations
from albot1.data.trajectory import read_tum, write_tum
from albot1.errors import Albot1Error
from albot1.records import Record, ResultRecord, dump_record, json_value, parse_record, read_record
from albot1.runs.errors import RunError
from albot1.runs.map_files import write_map
from albot1.versions import key_versions

DONE = "DONE"
RESULT_FILE = "result.json"
PER_SCAN_FILE = "per_scan_ns.npy"
METRICS_FILE = "metrics.json"
LATEST = "latest"
#: Files of a run that a new write of the same folder may not produce again (the metrics above all:
#: they belong to the older run); :func:`write_run` removes them first.
REWRITTEN_FILES = (
    METRICS_FILE,
    "reference.tum",
    "relations.txt",
    "map.geojson",
    "map.npz",
    "preview.png",
    "places.png",  # the preview's picture of a network of places (report/preview.py)
)
#: The files a run folder may hold (the bench's cell files included); a mapper's extra file must not take one.
STANDARD_FILES = frozenset(
    {
        "trajectory.tum",
        "odometry.tum",
        "reference.tum",
        "relations.txt",
        RESULT_FILE,
        "map.geojson",
        "map.npz",
        "extras.json",
        "preview.png",
        "places.png",
        PER_SCAN_FILE,
        METRICS_FILE,
        DONE,
        "cell.json",
        "cell.log",
        "attempt.json",
        "FAILED.json",
    }
)

#: Draws a run's ``preview.png`` (``albot1.report.preview.render_preview``). The caller passes it in:
#: storing a run must not depend on the plotting layer above it (docs/architecture.md, layers).
#: ``preset`` of a run folder holding another system's trajectory file (albot1.runs.external), not a method's run.
EXTERNAL_PRESET = "external"

PreviewRenderer = Callable[[RunResult, Path], None]


def run_key(
    dataset: str,
    method: str,
    config: dict[str, Any],
    degradation: str,
    seed: int,
    versions: Mapping[str, str | None],
    data: Mapping[str, str] | None = None,
    loader: Mapping[str, Any] | None = None,
) -> str:
    """Content hash naming a run folder (16 hex digits).

    ``data`` is the sha256 of every file the dataset was read from
    (``SequenceMetadata.checksums``): a log edited after its run gets a new
    key, so its old result is never taken for the new data's. A sequence read
    from no file (a synthetic world: its code version names it) keeps the key
    it had before checksums were recorded. ``loader`` is the ``[loader]``
    table of a registered dataset's manifest (``SequenceMetadata.manifest_loader``):
    a manifest edited or replaced (``ALBOT1_CONFIG_DIR``) with another
    ``max_range`` or odometry source reads other scans from the same files,
    and its name does not say so. ``versions`` is the run's versions block
    (``versions`` in ``result.json``, :func:`albot1.versions.run_versions`):
    the code version, the version of every recorded library, of the programs
    the method runs (MRPT's) and of a plugin method's distribution. All of it
    but the commit label is digested (:func:`albot1.versions.key_versions`),
    so a result computed with a library or program since upgraded, or by a
    plugin's older release, is not taken for what the new one computes.
    """
    fields: dict[str, Any] = {
        "dataset": dataset,
        "method": method,
        "config": config,
        "degradation": degradation,
        "seed": seed,
        "versions": key_versions(versions),
    }
    if data:
        fields["data"] = dict(data)
    if loader:
        fields["loader"] = dict(loader)
    payload = json.dumps(fields, sort_keys=True, default=str)
    return hashlib.sha256(payload.encode()).hexdigest()[:16]


def write_json(path: Path, data: Any) -> None:
    """Atomically write JSON (numpy values as Python ones, NaN/inf as null; key order kept)."""
    atomic_write(path, lambda p: p.write_text(json.dumps(json_value(data), indent=2, sort_keys=False) + "\n"))


def write_record(path: Path, record: Record) -> None:
    """Atomically write one record (``result.json``, ``metrics.json``, ...) in its fields' order."""
    write_json(path, dump_record(record))


def is_complete(run_dir: Path) -> bool:
    return (run_dir / DONE).is_file()


def write_run(result: RunResult, root: Path, *, preview: PreviewRenderer | None = None) -> Path:
    """Store ``result`` under ``root/<key>`` and mark it DONE; returns the folder.

    ``preview`` draws ``preview.png`` before DONE is written; without it the folder has no preview.
    """
    key = run_key(
        result.dataset,
        result.method,
        result.config,
        result.degradation,
        result.seed,
        result.versions,
        result.dataset_info.get("data_sha256"),
        result.dataset_info.get("manifest_loader"),
    )
    run_dir = root / key
    run_dir.mkdir(parents=True, exist_ok=True)
    (run_dir / DONE).unlink(missing_ok=True)
    remove_temporaries(run_dir)  # left by a writer killed in an earlier attempt
    for name in REWRITTEN_FILES:  # a re-run never leaves an older run's metrics, map or preview behind
        (run_dir / name).unlink(missing_ok=True)

    atomic_write(run_dir / "trajectory.tum", lambda p: write_tum(p, result.timestamps, result.poses))
    atomic_write(run_dir / "odometry.tum", lambda p: write_tum(p, result.timestamps, result.odometry))
    reference = result.reference
    if reference is not None:
        atomic_write(run_dir / "reference.tum", lambda p: write_tum(p, result.timestamps, reference))
    if result.relations is not None:
        write_relations(run_dir / "relations.txt", result.relations)  # atomic itself
    map_file = write_map(run_dir, result.map)
    write_json(run_dir / "extras.json", result.extras)
    _write_files(run_dir, result.files)
    info = {
        "key": key,
        "method": result.method,
        "dataset": result.dataset,
        "preset": result.preset,
        "degradation": result.degradation,
        "seed": result.seed,
        "scans": int(len(result.poses)),
        "config": result.config,
        "versions": result.versions,
        "dataset_info": result.dataset_info,
        "counters": result.counters,
        "timing": dump_record(result.timing()),
        "map_file": map_file,
        "has_reference": result.reference is not None,
        "relations": len(result.relations) if result.relations is not None else 0,
    }
    write_record(run_dir / RESULT_FILE, parse_record(ResultRecord, info, f"{run_dir / RESULT_FILE} (being written)"))
    atomic_write(run_dir / PER_SCAN_FILE, lambda p: _save_npy(p, result.per_scan_ns))
    if preview is not None:
        atomic_write(run_dir / "preview.png", lambda p: preview(result, p))
    atomic_write(run_dir / DONE, lambda p: p.write_text(key + "\n"))
    return run_dir


def _save_npy(path: Path, array: NDArray[np.int64]) -> None:
    with path.open("wb") as handle:  # a file object: np.save would append ".npy" to a name without it
        np.save(handle, array)


def _write_files(run_dir: Path, files: dict[str, Any]) -> None:
    """A mapper's extra files: text for a str, bytes as they are, anything else as JSON; names are checked."""
    for name, content in files.items():
        if not name or Path(name).name != name or name.startswith(".") or name in STANDARD_FILES:
            raise RunError(
                f"{run_dir}: extra file name {name!r} from the mapper; expected a plain file name that is not one "
                f"of the run folder's own ({', '.join(sorted(STANDARD_FILES))})"
            )
        if isinstance(content, str):
            atomic_write(run_dir / name, partial(Path.write_text, data=content, encoding="utf-8"))
        elif isinstance(content, bytes):
            atomic_write(run_dir / name, partial(Path.write_bytes, data=content))
        else:
            write_json(run_dir / name, content)


@dataclass
class StoredRun:
    """A run folder read back (what ``evaluate`` and the report consume); ``info`` is its ``result.json``."""

    path: Path
    info: ResultRecord
    timestamps: NDArray[np.float64]
    poses: NDArray[np.float64]
    odometry: NDArray[np.float64]
    reference: NDArray[np.float64] | None
    relations: Relations | None
    per_scan_ns: NDArray[np.int64]

    def load_map(self) -> MapData:
        """The run's map (``map.npz`` points or ``map.geojson`` segments); RunError naming the file if damaged."""
        map_file = _required(self.path, self.info.map_file)
        try:
            if map_file.suffix == ".npz":
                with np.load(map_file, allow_pickle=False) as npz:
                    return MapData(points=np.asarray(npz["points"], dtype=float).reshape(-1, 2))
            return _geojson_map(json.loads(map_file.read_text(encoding="utf-8")))
        except (OSError, ValueError, EOFError, KeyError, TypeError, IndexError, zipfile.BadZipFile) as exc:
            kind = (
                "a .npz archive with a 'points' array of (x, y)"
                if map_file.suffix == ".npz"
                else ("a GeoJSON FeatureCollection of LineString segments and MultiPoint points")
            )
            # numpy's words for a file that is no array suggest loading it unsafely (allow_pickle): not repeated
            detail = "not a numpy archive" if "pickle" in str(exc) else f"{type(exc).__name__}: {exc}"
            raise RunError(f"{map_file}: not a map this project wrote ({detail}); expected {kind}") from None


def _geojson_map(collection: Any) -> MapData:
    segments, props, points = [], [], None
    for feature in collection["features"]:
        geom = feature["geometry"]
        if geom["type"] == "LineString":
            (x1, y1), (x2, y2) = geom["coordinates"][0], geom["coordinates"][-1]
            segments.append([float(x1), float(y1), float(x2), float(y2)])
            props.append(feature.get("properties") or {})
        elif geom["type"] == "MultiPoint":
            points = np.asarray(geom["coordinates"], dtype=float).reshape(-1, 2)
    return MapData(segments=np.asarray(segments, dtype=float).reshape(-1, 4), points=points, segment_properties=props)


def read_run(run_dir: str | Path) -> StoredRun:
    """Read a complete run folder; RunError if it is missing, incomplete or a file of it is damaged.

    Every error names the file and what was expected of it (a parse error of
    a TUM or relations file also names its line).
    """
    path = Path(run_dir)
    info = read_result(path)
    stamps, poses = _scan_poses(path, "trajectory.tum", info.scans, None)
    odom = _scan_poses(path, "odometry.tum", info.scans, stamps)[1]
    reference = _scan_poses(path, "reference.tum", info.scans, stamps)[1] if info.has_reference else None
    # The copy holds the relations as they were scored: a repeated line in it is one its source counted (this
    # code writes a note saying how it read its source, which wins; copies written before the note counted every
    # line as listed), so "keep" reads every copy back as scored.
    relations = (
        read_relations(_required(path, "relations.txt"), warn_repeats=False, repeats="keep") if info.relations else None
    )
    # another system's trajectory (albot1.runs.external_run) has no per-scan times: an empty array
    per_scan = _read_per_scan(_required(path, PER_SCAN_FILE), 0 if info.preset == EXTERNAL_PRESET else info.scans)
    return StoredRun(path, info, stamps, poses, odom, reference, relations, per_scan)


def _scan_poses(
    run_dir: Path, name: str, scans: int, stamps: NDArray[np.float64] | None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One of the run's TUM files: one pose per scan at the scans' stamps, or a RunError naming the file.

    :func:`write_run` writes the three files from one array of stamps, with ``scans`` rows each. A file cut
    short (a copy or sync that stopped early) or edited parses as a valid shorter trajectory; scored as it
    was, every metric would read "does not apply" (or, cut at both ends alike, score fewer scans) with exit 0,
    so the damage is said here, once, as the damage it is.
    """
    file = _required(run_dir, name)
    found_stamps, poses = read_tum(file)
    damaged = "the folder was damaged or edited by hand; run it again"
    if len(poses) != scans:
        raise RunError(
            f"{file}: {len(poses)} poses, expected {scans} (one per scan, as {RESULT_FILE} 'scans' says); {damaged}"
        )
    if stamps is not None and not np.array_equal(found_stamps, stamps):
        row = int(np.flatnonzero(found_stamps != stamps)[0])
        raise RunError(
            f"{file}: pose {row + 1} has stamp {found_stamps[row]:.9f}, expected {stamps[row]:.9f} (that scan's "
            f"stamp in trajectory.tum: the run's files are written from one array of stamps); {damaged}"
        )
    return found_stamps, poses


def _required(run_dir: Path, name: str) -> Path:
    """``run_dir / name``, or a RunError saying the complete run lacks it."""
    file = run_dir / name
    if not file.is_file():
        raise RunError(
            f"{file}: missing from a run folder marked complete; the folder was damaged or edited by hand "
            "(expected every file of docs/architecture.md's run-folder contract); run it again"
        )
    return file


def _read_per_scan(file: Path, scans: int) -> NDArray[np.int64]:
    """The per-scan times: a .npy array of ``scans`` non-negative integers (ns); RunError naming the file otherwise."""
    expected = f"expected a .npy array of {scans} per-scan times in integer nanoseconds (numpy.save)"
    try:
        array = np.load(file, allow_pickle=False)
    except (OSError, ValueError, EOFError):  # numpy's own words would suggest loading the file unsafely
        raise RunError(f"{file}: not a numpy array file this project wrote; {expected}") from None
    if not isinstance(array, np.ndarray) or array.dtype.kind not in "iu" or array.shape != (scans,):
        found = f"{getattr(array, 'dtype', type(array).__name__)} of shape {getattr(array, 'shape', '?')}"
        raise RunError(f"{file}: holds {found}; {expected}")
    return array.astype(np.int64, copy=False)


def read_result(run_dir: str | Path) -> ResultRecord:
    """The ``result.json`` of a complete run folder.

    RunError when the folder is not a run or is incomplete; RecordError when the file does not fit its model.
    """
    path = Path(run_dir)
    if not (path / RESULT_FILE).is_file():
        raise RunError(f"{path}: not a run folder (no {RESULT_FILE})")
    if not is_complete(path):
        raise RunError(f"{path}: the run is incomplete (no {DONE} marker); run it again")
    return read_record(ResultRecord, path / RESULT_FILE)


def mark_latest(root: Path, run_dir: Path) -> Path:
    """Point ``root/latest`` at ``run_dir`` (a relative symbolic link, replaced atomically); returns the link.

    Run folders are named by a content hash; ``runs/latest`` is the one a
    person just made. RunError when ``root/latest`` exists and is not a link.
    """
    link = root / LATEST
    if link.exists() and not link.is_symlink():
        raise RunError(f"{link}: exists and is not a symbolic link; cannot mark the latest run there")
    tmp = root / f".{LATEST}.{os.getpid()}"
    tmp.unlink(missing_ok=True)
    os.symlink(os.path.relpath(run_dir, root), tmp)
    os.replace(tmp, link)
    return link


@dataclass(frozen=True)
class RunListing:
    """One folder under a runs root, as ``albot1 runs`` lists it."""

    path: Path
    status: str  # done | evaluated | incomplete | failed | unreadable
    info: ResultRecord | None
    modified: float
    problem: str | None = None


def list_runs(root: Path) -> list[RunListing]:
    """Every run folder directly under ``root`` (oldest first); folders that are not runs are left out.

    A folder is a run when it holds ``result.json``, ``DONE`` or the bench's
    ``FAILED.json``; one whose ``result.json`` does not read is listed as
    unreadable with the reason, never skipped.
    """
    if not root.is_dir():
        raise RunError(f"{root}: not a folder of runs")
    out: list[RunListing] = []
    for folder in sorted(p for p in root.iterdir() if p.is_dir() and not p.is_symlink()):
        markers = [folder / name for name in (RESULT_FILE, DONE, "FAILED.json")]
        present = [m for m in markers if m.exists()]
        if not present:
            continue
        modified = max(m.stat().st_mtime for m in present)
        if not (folder / RESULT_FILE).is_file():
            failed = (folder / "FAILED.json").is_file()
            out.append(RunListing(folder, "failed" if failed else "incomplete", None, modified))
            continue
        try:
            info = read_record(ResultRecord, folder / RESULT_FILE)
        except Albot1Error as exc:
            out.append(RunListing(folder, "unreadable", None, modified, str(exc)))
            continue
        if not is_complete(folder):
            status = "incomplete"
        else:
            status = "evaluated" if (folder / METRICS_FILE).is_file() else "done"
        out.append(RunListing(folder, status, info, modified))
    return sorted(out, key=lambda r: (r.modified, r.path.name))
