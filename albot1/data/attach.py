"""A user's own ground truth attached to any source: ``?relations=FILE`` and ``?reference=FILE``.

Every source (ROS1 bag, ROS2 sqlite3/MCAP bag, own log, CARMEN log,
synthetic world, catalog dataset) takes the two options; they are applied
by :func:`albot1.data.open.open_sequence`, not by each loader, so they mean
the same everywhere (``docs/formats.md``, "Options of every source"):

``relations=FILE``
    a relations file (:mod:`albot1.data.relations`) replaces the source's own
    relations (if any); the relation metric then scores against it. A file
    none of whose relation stamps lies within the log's time span (another
    log's relations), or one with a relation end within that span that is no
    scan's stamp, is refused on the first full pass over the scans.
    ``relations_repeats=drop|keep`` says how its identically repeated lines
    count: once (drop, the default) or as listed (keep, the published
    evaluator's reading).
``reference=FILE``
    a reference trajectory (TUM, KITTI or a corrected CARMEN log;
    :mod:`albot1.data.trajectory`, format from the file) gives every scan its
    reference pose, replacing the source's own: with timestamps (TUM,
    CARMEN) each scan takes the file's pose nearest in time, which must lie
    within ``reference_max_dt`` seconds (default :data:`REFERENCE_MAX_DT_S`,
    evo's ``t_max_diff``); without (KITTI) the file must hold one pose per
    scan, in order. A scan without a pose is an error naming the scan: the
    reference is all or nothing (a metric scored on part of the scans would
    not say which part).

CARMEN logs have their own ``reference`` keyword (:data:`~albot1.data.loaders.base.REFERENCE_KEYWORDS`:
which lines hold the reference); any other value of ``reference`` names a file.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import numpy as np

from albot1.data.errors import DataError, ReferenceOptionError
from albot1.data.model import Frame, Relations, Sequence
from albot1.data.relations import STAMP_TOLERANCE_S, match_stamps, read_relations, repeat_policy
from albot1.data.trajectory import read_trajectory

#: Largest gap (s) between a scan and the reference pose it takes (evo's default ``t_max_diff``).
REFERENCE_MAX_DT_S = 0.01
#: How many relations an error about relation ends between scans names.
_NAMED = 3


def with_relations(sequence: Sequence, value: object, ref: str, repeats: object = None) -> Sequence:
    """``sequence`` whose relations are read from the file ``value`` (the ``relations=FILE`` option).

    ``repeats`` is the ``relations_repeats`` option (how identical repeated lines count), default drop.
    """
    path = _file(value, "relations", ref)
    relations = read_relations(path, repeats="drop" if repeats is None else repeat_policy(repeats, repr(ref)))
    extra = {**sequence.metadata.extra, "relations_file": str(path)}
    out = sequence.with_frames(
        lambda frames: _of_this_log(frames, relations, path, ref),
        metadata=replace(sequence.metadata, extra=extra),
        scan_count=sequence.known_scan_count,
    )
    out.relations = relations
    return out


def _of_this_log(frames: Iterator[Frame], relations: Relations, path: Path, ref: str) -> Iterator[Frame]:
    """``frames`` unchanged; once they are all seen, ReferenceOptionError if no relation stamp lies in their time,
    or if one within their time names no scan.

    Relations of another log would otherwise be counted (``datasets info``)
    and then all left out by the relation metric as naming scans the run did
    not see. The log's time span is known only after a pass over its scans,
    so the check rides on the first full pass that is made anyway (a sliced
    reference stops early and is not checked: its relations may well lie
    outside the slice). Any overlap, within :data:`STAMP_TOLERANCE_S` (the
    relation metric's matching tolerance), passes: partial overlap is
    counted and reported by the metric.

    A relation end *within* the log's time that is no scan's stamp (between two
    scans: a file rounded to milliseconds, another clock, a typo) is refused
    too, naming the first such relations: the relation metric matches ends to
    scans within 0.1 ms and would leave such a relation out as naming "a scan
    the run did not see", scoring the rest as if the file were complete.
    """
    seen: list[float] = []
    for frame in frames:
        t = frame.scan.timestamp
        if math.isfinite(t):
            seen.append(t)
        yield frame
    if not len(relations) or not seen:
        return
    scans = np.asarray(seen, dtype=float)
    first, last = float(scans.min()), float(scans.max())
    stamps = np.concatenate([relations.t1, relations.t2])
    inside = (stamps >= first - STAMP_TOLERANCE_S) & (stamps <= last + STAMP_TOLERANCE_S)
    if not np.any(inside):
        raise ReferenceOptionError(
            f"{path}: its {len(relations)} relations span {stamps.min():.3f}-{stamps.max():.3f} s, but the scans "
            f"of {ref!r} span {first:.3f}-{last:.3f} s: no relation lies within the log's time; expected the "
            "relations of this log"
        )
    _, gap = match_stamps(scans, stamps)
    between = np.flatnonzero(inside & (gap > STAMP_TOLERANCE_S)) % len(relations)
    if len(between):
        bad = np.unique(between)
        named = ", ".join(f"{k + 1} ({relations.t1[k]:.6f} -> {relations.t2[k]:.6f})" for k in bad[:_NAMED]) + (
            ", ..." if len(bad) > _NAMED else ""
        )
        raise ReferenceOptionError(
            f"{path}: {len(bad)} of its {len(relations)} relations have an end within the time of {ref!r} "
            f"({first:.3f}-{last:.3f} s) that is no scan's stamp (none within {STAMP_TOLERANCE_S:g} s): relation "
            f"{named}; expected every relation end to be the stamp of a scan of this log"
        )


def with_reference(sequence: Sequence, value: object, ref: str, max_dt: object = None) -> Sequence:
    """``sequence`` whose frames carry the reference poses of the file ``value`` (the ``reference=FILE`` option)."""
    path = _file(value, "reference", ref)
    limit = REFERENCE_MAX_DT_S if max_dt is None else _seconds(max_dt, ref)
    poses = read_trajectory(path)
    stamps = poses.timestamps
    if not len(poses.poses):
        raise DataError(f"{path}: the reference trajectory holds no poses")

    order = None if stamps is None else np.argsort(stamps, kind="stable")
    sorted_stamps = None if stamps is None or order is None else stamps[order]

    def pose_of(frame: Frame) -> np.ndarray:
        if sorted_stamps is None or order is None:
            if frame.index >= len(poses.poses):
                raise ReferenceOptionError(
                    f"{path}: {len(poses.poses)} poses ({poses.format}, no timestamps), but {ref!r} has more "
                    "scans; expected one pose per scan in order"
                )
            return np.array(poses.poses[frame.index], dtype=float)
        t = frame.scan.timestamp
        right = min(int(np.searchsorted(sorted_stamps, t)), len(sorted_stamps) - 1)
        left = max(right - 1, 0)
        pick = left if abs(sorted_stamps[left] - t) < abs(sorted_stamps[right] - t) else right
        gap = abs(sorted_stamps[pick] - t)
        if not gap <= limit:
            raise ReferenceOptionError(
                f"{path}: no pose within {limit:g} s of scan {frame.index} of {ref!r} (t = {t:.6f} s; nearest "
                f"{gap:.3g} s away; the file spans {sorted_stamps[0]:.3f}-{sorted_stamps[-1]:.3f} s); expected "
                "a pose for every scan (raise reference_max_dt=S, or slice the scans)"
            )
        return np.array(poses.poses[int(order[pick])], dtype=float)

    def attach(frames: Iterator[Frame]) -> Iterator[Frame]:
        count = 0
        for frame in frames:
            count += 1
            yield replace(frame, reference=pose_of(frame))
        if stamps is None and count != len(poses.poses):
            raise ReferenceOptionError(
                f"{path}: {len(poses.poses)} poses ({poses.format}, no timestamps), but {ref!r} has {count} "
                "scans; expected one pose per scan in order"
            )

    source = f"reference poses of {path} ({poses.format})"
    return sequence.with_frames(
        attach,
        metadata=replace(sequence.metadata, reference_source=source),
        scan_count=sequence.known_scan_count,
    )


def _file(value: object, option: str, ref: str) -> Path:
    path = Path(str(value)).expanduser()
    if not str(value):
        raise ReferenceOptionError(f"{ref!r}: {option}= names no file; expected {option}=FILE")
    if path.is_dir():
        raise ReferenceOptionError(f"{ref!r}: {option}={value} is a folder; expected a file")
    if not path.is_file():
        raise ReferenceOptionError(f"{ref!r}: {option}={value}: no such file")
    return path


def _seconds(value: object, ref: str) -> float:
    try:
        seconds = float(str(value))
    except ValueError:
        seconds = float("nan")
    if not (np.isfinite(seconds) and seconds > 0):
        raise ReferenceOptionError(f"{ref!r}: reference_max_dt={value}; expected a positive number of seconds")
    return seconds
