"""An external trajectory (Cartographer, slam_toolbox, GMapping, ...) prepared for scoring against a dataset.

The file's poses (:func:`albot1.data.trajectory.read_trajectory`) are
matched to the dataset's scans, whose reference poses they are scored
against:

* **by time** (TUM, CARMEN): each pose goes to the scan nearest in time
  (:func:`albot1.data.relations.match_stamps`, the lookup the relation
  metric uses) when that scan is at most ``max_dt_s`` away (default
  :data:`MAX_DT_S`, evo's default ``t_max_diff``); when several poses go
  to one scan the nearest keeps it (the earlier on a tie). Every pose left
  out is counted in the ``trajectory`` block of ``metrics.json`` and by
  the CLI, never dropped silently;
* **by order** (KITTI, no timestamps): the file must hold exactly one pose
  per scan of the dataset (``NAME[:N]`` selects a prefix);
* **by line**, when the file's timestamps are the scans' own, line for line,
  and some repeat, and the file is a run's own ``trajectory.tum`` in its run
  folder, whose ``result.json`` records this dataset reference and as many
  scans (:func:`paired_by_line`): a log whose scans share a stamp (the
  corrected Radish logs stamp every scan 0). It pairs as the run itself
  scored it, scan by scan. Two poses at one time cannot be told apart by
  time, and equal stamps do not prove equal scans (``NAME[:200:2]`` and
  ``NAME[:100]`` both stamp 0), so any other file whose timestamps repeat
  is refused, suggesting ``albot1 evaluate RUN_DIR``.

Every metric, the relation metric included, scores the matched poses
stamped with their scans' stamps: a relation names two scans by their
stamps, so a pose printed with fewer decimals, or a little late, is still
its scan's pose (looked up at the file's own stamps, such relations were
left out as if the file had no pose for them). Map shape, update counts and cost need
a map, counters and timings that a trajectory file does not hold: those
metrics are null with that reason.
"""

from __future__ import annotations

import hashlib
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1 import versions
from albot1.data.model import Relations, Sequence
from albot1.data.open import open_sequence
from albot1.data.relations import match_stamps, read_relations, write_relations
from albot1.data.trajectory import (
    PoseFile,
    as_stored,
    has_repeated_stamps,
    read_trajectory,
    stamps_as_stored,
)
from albot1.errors import Albot1Error
from albot1.runs.errors import RunError
from albot1.runs.folder import EXTERNAL_PRESET, read_result
from albot1.runs.scored import Scored
from albot1.settings import Settings

#: Largest time between a pose and the scan it is matched to (s): evo's default ``t_max_diff``.
MAX_DT_S = 0.01
NO_MAP = "an external trajectory comes without a map"
NO_COUNTERS = "an external trajectory comes without the method's counters (views, updates)"
NO_TIMING = "an external trajectory comes without per-scan timings"
#: The TUM files a run folder holds, one pose per scan of the run (``albot1.runs.folder``).
RUN_TUM_FILES = ("trajectory.tum", "odometry.tum", "reference.tum")


@dataclass(frozen=True)
class Matching:
    """Which pose of the file went to which scan, and how many poses were left out (and why)."""

    pose_index: NDArray[np.int64]
    scan_index: NDArray[np.int64]
    unmatched: int
    duplicates: int


def match_by_time(pose_times: NDArray[np.float64], scan_times: NDArray[np.float64], max_dt_s: float) -> Matching:
    """Each pose to its nearest scan within ``max_dt_s``; one pose per scan (the nearest; ties: the earlier pose).

    The result is ordered by scan index.
    """
    if not len(pose_times) or not len(scan_times):
        return Matching(np.empty(0, np.int64), np.empty(0, np.int64), int(len(pose_times)), 0)
    scan, gap = match_stamps(scan_times, pose_times)
    close = np.flatnonzero(gap <= max_dt_s)
    # nearest pose per scan: sort by (scan, gap, pose index) and keep the first of each scan
    order = np.lexsort((close, gap[close], scan[close]))
    chosen = close[order]
    first = np.concatenate([[True], scan[chosen][1:] != scan[chosen][:-1]]) if len(chosen) else np.empty(0, bool)
    keep = chosen[first]
    return Matching(
        pose_index=keep.astype(np.int64),
        scan_index=scan[keep].astype(np.int64),
        unmatched=int(len(pose_times) - len(close)),
        duplicates=int(len(close) - len(keep)),
    )


def paired_by_line(
    stamps: NDArray[np.float64] | None,
    other: NDArray[np.float64] | None,
    files: tuple[Path, ...],
    *,
    dataset: str | None = None,
) -> bool:
    """Whether poses stamped ``stamps`` pair with those stamped ``other`` line by line rather than by time.

    So they do when both hold the same timestamps in the same order, some
    repeat, and ``files`` are a run's own TUM files in its run folder
    (:func:`from_one_run`, of ``dataset`` when given): the files a run writes
    for a log whose scans share a stamp, which the run scored scan by scan.
    Equal stamps alone prove nothing: every scan of a corrected Radish log is
    stamped 0, so ``belgioioso-corrected[:200:2]`` and ``[:100]`` hold the
    same stamps but other scans. Matched by time, two poses at one time
    could not be told apart. Stamps that never repeat pair by time, as any
    file does (a time offset shifts one side, so its lines then differ).
    """
    return (
        stamps is not None
        and other is not None
        and has_repeated_stamps(other)
        and bool(np.array_equal(stamps, other))
        and from_one_run(files, len(other), dataset=dataset)
    )


def from_one_run(files: tuple[Path, ...], scans: int, *, dataset: str | None = None) -> bool:
    """Whether ``files`` are TUM files a run wrote (:data:`RUN_TUM_FILES`) in one complete run folder.

    That folder's ``result.json`` must record ``scans`` scans, and ``dataset``
    as its dataset reference when given: then every file holds one pose per
    scan of that one selection of scans, the proof that line pairs with line.
    A file copied out of its folder, or renamed, proves nothing and is refused.
    """
    real = [file.resolve() for file in files]
    folders = {file.parent for file in real}
    if len(folders) != 1 or any(file.name not in RUN_TUM_FILES for file in real):
        return False
    try:
        result = read_result(folders.pop())
    except Albot1Error:
        return False
    return result.scans == scans and (dataset is None or result.dataset == dataset)


def refuse_repeated_stamps_by_time(file: PoseFile, others: int, what: str) -> None:
    """RunError when ``file``'s timestamps repeat and its poses must be matched to ``others`` ``what`` by time.

    Which of two poses at one time is meant cannot be told, so the file is
    refused; the one case that pairs line by line is a run's own files
    (:func:`paired_by_line`), which ``albot1 evaluate RUN_DIR`` scores.
    """
    stamps = file.timestamps
    if stamps is None or not has_repeated_stamps(stamps):
        return
    distinct = len(np.unique(stamps))
    raise RunError(
        f"{file.path}: {len(file.poses)} poses for {others} {what}, and its timestamps repeat ({distinct} distinct "
        f"value{'s' if distinct != 1 else ''}), so the poses cannot be matched by time; only a run's own files in "
        "its run folder pair line by line: to score a run, give `albot1 evaluate RUN_DIR`"
    )


def load_external(
    path: Path,
    dataset: str,
    *,
    format_name: str | None = None,
    label: str | None = None,
    max_dt_s: float | None = None,
    settings: Settings | None = None,
    wrap: Callable[[Sequence], Sequence] | None = None,
    time_offset_s: float = 0.0,
) -> Scored:
    """The trajectory in ``path`` matched to ``dataset``'s scans, ready for :func:`albot1.runs.evaluate.score`.

    ``wrap`` may wrap the opened dataset before its one decoding pass (the CLI's progress bar);
    ``time_offset_s`` is added to the file's timestamps before matching (evo's ``--t_offset``).
    """
    file = read_trajectory(path, format_name, repeated_stamps=True)
    if time_offset_s and file.timestamps is None:
        raise RunError(f"{file.path}: --time-offset needs timestamps; a {file.format} file has none")
    if time_offset_s and file.timestamps is not None:
        file = replace(file, timestamps=file.timestamps + time_offset_s)
    if max_dt_s is not None and not max_dt_s > 0:
        raise RunError(f"--max-dt is {max_dt_s} s; expected a positive number of seconds")
    if not len(file.poses):
        raise RunError(f"{file.path}: the trajectory holds no poses")
    sequence = open_sequence(dataset, settings=settings)
    if wrap is not None:
        sequence = wrap(sequence)
    arrays = sequence.arrays  # one decoding pass: scan times and reference poses
    scan_times, reference = arrays.timestamps, arrays.reference
    if reference is not None:
        reference = as_stored(scan_times, reference)  # as a run folder's reference.tum holds it
    stamps, stored_times = file.timestamps, stamps_as_stored(scan_times)
    if stamps is not None and paired_by_line(stamps, stored_times, (file.path,), dataset=dataset):
        dt = None
        matching = Matching(np.arange(len(scan_times)), np.arange(len(scan_times)), 0, 0)
    elif file.timestamps is None:
        if len(file.poses) != len(scan_times):
            raise RunError(
                f"{file.path}: {len(file.poses)} poses without timestamps ({file.format}), but dataset {dataset!r} "
                f"has {len(scan_times)} scans; expected one pose per scan in order (select a prefix with NAME[:N])"
            )
        dt = None
        matching = Matching(np.arange(len(scan_times)), np.arange(len(scan_times)), 0, 0)
    else:
        refuse_repeated_stamps_by_time(file, len(scan_times), f"scans of {dataset!r}")
        dt = MAX_DT_S if max_dt_s is None else max_dt_s
        matching = match_by_time(file.timestamps, scan_times, dt)
        if not len(matching.pose_index):
            raise RunError(
                f"{file.path}: none of its {len(file.poses)} poses (times {file.timestamps.min():.3f}-"
                f"{file.timestamps.max():.3f} s) lies within {dt:g} s of a scan of {dataset!r} (times "
                f"{scan_times.min():.3f}-{scan_times.max():.3f} s); expected the log's own timestamps"
            )
    poses = file.poses[matching.pose_index]
    scans = matching.scan_index
    # A matched pose is its scan's pose, stamped as the run folder stamps that scan: a relation names scans by
    # their stamps, so looking relations up at the file's own stamps left out every relation whose pose was
    # printed with fewer decimals or a little late (0.5 ms: within --max-dt, beyond the 0.1 ms relation
    # tolerance), as if the trajectory had no pose for that scan, and scored the rest.
    times = stored_times[scans]
    key, digest = _key(file, dataset)
    name = label or file.path.stem
    return Scored(
        header={
            "key": key,
            "method": name,
            "dataset": dataset,
            "preset": EXTERNAL_PRESET,
            "degradation": "none",
            "seed": None,
            "scans": int(len(poses)),
            "has_reference": reference is not None,
        },
        dataset=dataset,
        timestamps=times,
        poses=poses,
        reference=reference[scans] if reference is not None else None,
        relations=_as_stored(sequence.relations),
        relations_source=f"the relations of {dataset}",
        relation_timestamps=times,
        relation_poses=poses,
        absent={"map_shape": NO_MAP, "updates": NO_COUNTERS, "cost": NO_TIMING},
        extra={
            "trajectory": {
                "file": str(file.path),
                "format": file.format,
                "sha256": digest,
                "poses": int(len(file.poses)),
                "matched": int(len(poses)),
                "unmatched": matching.unmatched,
                "duplicates": matching.duplicates,
                "max_dt_s": dt,
                "versions": {"code": versions.code_version(), "git": versions.git_commit()},
                "reference_without_pose": int(len(scan_times) - len(poses)) if reference is not None else None,
                "time_offset_s": time_offset_s or None,
            }
        },
    )


def _key(file: PoseFile, dataset: str) -> tuple[str, str]:
    """(evaluation key, sha256 of the file): the key names the file's content, its format and the dataset."""
    digest = hashlib.sha256(file.path.read_bytes()).hexdigest()
    key = hashlib.sha256(f"{digest}\n{file.format}\n{dataset}".encode()).hexdigest()[:16]
    return key, digest


def _as_stored(relations: Relations | None) -> Relations | None:
    """``relations`` exactly as a run folder's ``relations.txt`` holds them (written and read back).

    Like the reference poses (:func:`albot1.data.trajectory.as_stored`), so
    a run folder and its trajectory scored as a file give the same numbers.
    """
    if relations is None:
        return None
    with tempfile.TemporaryDirectory(prefix="albot1-relations-") as folder:
        path = Path(folder) / "relations.txt"
        write_relations(path, relations)
        # the dataset's own file already warned about its repeated lines; this copy repeated it naming a temporary file
        return read_relations(path, empty_ok=True, warn_repeats=False)
