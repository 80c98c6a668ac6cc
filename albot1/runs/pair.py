"""Two trajectory files scored against each other (``albot1 evaluate --trajectory EST --reference REF``).

Like ``evo_ape``/``evo_rpe``, no dataset is needed: the reference file
(TUM, KITTI or a corrected CARMEN log) plays the dataset's reference poses.

* **Association.** With timestamps on both sides, each estimate pose, its
  time plus ``time_offset_s`` (evo's ``--t_offset``), goes to the reference
  pose nearest in time within ``max_dt_s`` (evo's ``--t_max_diff``, default
  0.01 s); one estimate pose per reference pose, the nearest
  (:func:`albot1.runs.external.match_by_time`, the rule of scoring against a
  dataset). Estimate poses left out and reference poses without an estimate
  are counted in the ``trajectory`` block and by the CLI. Without
  timestamps on either side (KITTI), the two files must hold as many poses,
  matched in order, and a time offset does not apply. Two poses of one
  file with one timestamp cannot be told apart by time and are refused,
  except where both files hold the very same timestamps line for line and
  are TUM files of one run folder with as many scans: the
  ``trajectory.tum`` and ``reference.tum`` of one run on a log whose scans
  share stamps (the corrected Radish logs stamp every scan 0; equal stamps
  alone do not prove equal scans, as ``NAME[:200:2]`` and ``NAME[:100]``
  both stamp 0). Those pair
  in order, one line with the same line of the other, as the run's own
  scoring pairs them scan by scan (``max_dt_s`` null, as for KITTI;
  :func:`albot1.runs.external.paired_by_line`, the rule of scoring against a dataset).
* **Alignment** of the ATE (:func:`parse_alignment`): ``se2`` (rigid, the
  default; evo's ``--align`` without scale), ``origin`` (evo's
  ``--align_origin``), ``first:N`` (rigid, estimated on the first N pairs;
  evo's ``--align --n_to_align N``) or ``none``. Every other metric is
  alignment-free (relative poses) or aligns on its own terms (windows).

Map shape, update counts and cost need what a trajectory file does not
hold, relations need a relations file: those metrics are null with that reason.
"""

from __future__ import annotations

import hashlib
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np

from albot1 import versions
from albot1.data.trajectory import PoseFile, read_trajectory
from albot1.runs.errors import RunError
from albot1.runs.external import (
    MAX_DT_S,
    NO_COUNTERS,
    NO_MAP,
    NO_TIMING,
    Matching,
    match_by_time,
    paired_by_line,
    refuse_repeated_stamps_by_time,
)
from albot1.runs.folder import EXTERNAL_PRESET
from albot1.runs.scored import Scored

#: The alignment choices of ``--align`` (``first:N`` with a positive N), in the words evo users know.
ALIGN_CHOICES = ("se2", "origin", "first:N", "none")
NO_RELATIONS = "scored against a reference trajectory file, which has no relations"


def parse_alignment(text: str) -> tuple[str, int | None]:
    """``"se2"`` -> ``("rigid", None)``; ``"origin"`` -> ``("first", None)``; ``"first:10"`` -> ``("rigid", 10)``."""
    value = text.strip().lower()
    if value in ("se2", "rigid"):
        return "rigid", None
    if value in ("origin", "none"):
        return ("first" if value == "origin" else "none"), None
    found = re.fullmatch(r"first:([0-9]{1,9})", value)
    if found is not None and int(found[1]) >= 1:
        return "rigid", int(found[1])
    raise RunError(
        f"--align {text[:40]!r} is not understood; expected {' | '.join(ALIGN_CHOICES)} (se2: rigid on all pairs, "
        "origin: first poses made equal, first:N: rigid on the first N pairs with N >= 1, none: as they are)"
    )


def with_alignment(scored: Scored, align: str | None) -> Scored:
    """``scored`` with the ATE alignment of ``--align`` (unchanged when None), recorded in its trajectory block."""
    if align is None:
        return scored
    method, n = parse_alignment(align)
    if n is not None and n > len(scored.poses):
        raise RunError(f"--align first:{n}: only {len(scored.poses)} pose pairs were matched; expected N <= that")
    extra = dict(scored.extra)
    if "trajectory" in extra:
        extra["trajectory"] = {**extra["trajectory"], "alignment": align.strip().lower()}
    return replace(scored, alignment=method, n_to_align=n, extra=extra)  # type: ignore[arg-type]


def check_time_offset(time_offset_s: float | None) -> float:
    """The offset (s), 0 when None; RunError when it is not a finite number."""
    if time_offset_s is None:
        return 0.0
    if not math.isfinite(time_offset_s) or abs(time_offset_s) > 1e9:
        raise RunError(f"--time-offset is {time_offset_s}; expected a finite number of seconds")
    return float(time_offset_s)


def load_pair(
    estimate: Path,
    reference: Path,
    *,
    format_name: str | None = None,
    reference_format: str | None = None,
    label: str | None = None,
    max_dt_s: float | None = None,
    time_offset_s: float | None = None,
    align: str | None = None,
) -> Scored:
    """The estimate file matched to the reference file, ready for :func:`albot1.runs.evaluate.score`."""
    if align is not None:
        parse_alignment(align)  # refuse a bad choice before reading anything
    offset = check_time_offset(time_offset_s)
    if max_dt_s is not None and not (math.isfinite(max_dt_s) and max_dt_s > 0):
        raise RunError(f"--max-dt is {max_dt_s} s; expected a positive number of seconds")
    est = read_trajectory(estimate, format_name, repeated_stamps=True)
    ref = read_trajectory(reference, reference_format, repeated_stamps=True)
    for file, role in ((est, "trajectory"), (ref, "reference")):
        if not len(file.poses):
            raise RunError(f"{file.path}: the {role} holds no poses")
    if (
        ref.timestamps is not None
        and est.timestamps is not None
        and paired_by_line(est.timestamps + offset, ref.timestamps, (est.path, ref.path))
    ):
        dt = None
        matching = Matching(np.arange(len(ref.poses)), np.arange(len(ref.poses)), 0, 0)
        est_times = ref_times = ref.timestamps
    elif est.timestamps is None or ref.timestamps is None:
        if offset:
            raise RunError("--time-offset needs timestamps in both files; a KITTI file has none")
        if len(est.poses) != len(ref.poses):
            raise RunError(
                f"{est.path}: {len(est.poses)} poses, {ref.path}: {len(ref.poses)} poses; without timestamps "
                "(KITTI) the two files must hold one pose each per step, in order"
            )
        dt = None
        matching = Matching(np.arange(len(ref.poses)), np.arange(len(ref.poses)), 0, 0)
        est_times = ref_times = np.arange(len(ref.poses), dtype=float)
    else:
        refuse_repeated_stamps_by_time(est, len(ref.poses), f"reference poses of {ref.path}")
        refuse_repeated_stamps_by_time(ref, len(est.poses), f"poses of {est.path}")
        dt = MAX_DT_S if max_dt_s is None else max_dt_s
        est_times, ref_times = est.timestamps + offset, ref.timestamps
        matching = match_by_time(est_times, ref_times, dt)
        if not len(matching.pose_index):
            raise RunError(
                f"{est.path}: none of its {len(est.poses)} poses (times {est_times.min():.3f}-{est_times.max():.3f} s"
                f"{f' after the offset of {offset:g} s' if offset else ''}) lies within {dt:g} s of a pose of "
                f"{ref.path} (times {ref_times.min():.3f}-{ref_times.max():.3f} s); expected one clock (or give "
                "--time-offset)"
            )
    # In time order, not the reference file's line order: ATE's origin alignment, RPE, drift and loop gap read
    # the pairs as a path (a reference file listed out of order scored 2.3 m of RPE for a path with 0.1 m).
    in_time = np.argsort(ref_times[matching.scan_index], kind="stable")
    matching = replace(matching, pose_index=matching.pose_index[in_time], scan_index=matching.scan_index[in_time])
    poses = est.poses[matching.pose_index]
    order = np.argsort(est_times, kind="stable")
    est_digest, ref_digest = _sha256(est.path), _sha256(ref.path)
    name = label or est.path.stem
    key = hashlib.sha256(
        f"{est_digest}\n{est.format}\n{ref_digest}\n{ref.format}\n{offset!r}\n{dt!r}".encode()
    ).hexdigest()[:16]
    scored = Scored(
        header={
            "key": key,
            "method": name,
            "dataset": str(ref.path),
            "preset": EXTERNAL_PRESET,
            "degradation": "none",
            "seed": None,
            "scans": int(len(poses)),
            "has_reference": True,
        },
        dataset=str(ref.path),
        timestamps=est_times[matching.pose_index],
        poses=poses,
        reference=ref.poses[matching.scan_index],
        relations=None,
        relations_source=str(ref.path),
        relation_timestamps=est_times[order],
        relation_poses=est.poses[order],
        absent={"map_shape": NO_MAP, "updates": NO_COUNTERS, "cost": NO_TIMING, "relations": NO_RELATIONS},
        extra={"trajectory": _source(est, ref, est_digest, ref_digest, matching, dt, offset)},
    )
    return with_alignment(scored, align)


def _source(
    est: PoseFile,
    ref: PoseFile,
    est_digest: str,
    ref_digest: str,
    matching: Matching,
    dt: float | None,
    offset: float,
) -> dict[str, object]:
    """The ``trajectory`` block of ``metrics.json`` for a pair of files."""
    return {
        "file": str(est.path),
        "format": est.format,
        "sha256": est_digest,
        "poses": int(len(est.poses)),
        "matched": int(len(matching.pose_index)),
        "unmatched": matching.unmatched,
        "duplicates": matching.duplicates,
        "max_dt_s": dt,
        "versions": {"code": versions.code_version(), "git": versions.git_commit()},
        "reference_without_pose": int(len(ref.poses) - len(matching.scan_index)),
        "reference_file": str(ref.path),
        "reference_format": ref.format,
        "reference_sha256": ref_digest,
        "reference_poses": int(len(ref.poses)),
        "time_offset_s": offset or None,
    }


def _sha256(path: Path) -> str:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError as exc:  # pragma: no cover - the file was just read
        raise RunError(f"{path}: cannot read: {exc.strerror or exc}") from None
