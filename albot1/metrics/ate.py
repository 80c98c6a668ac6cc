"""Absolute trajectory error (ATE) with an explicit SE(2) alignment.

The estimate is aligned to the reference (:mod:`albot1.metrics.alignment`),
then each scan's error is the Euclidean distance between the aligned and the
reference position (metres) and the absolute heading difference (degrees).
Statistics use evo's conventions (population std, ``rmse`` over all scans),
so the numbers equal ``evo_ape tum REF EST --align`` (translation part) for
``rigid`` and ``--align_origin`` for ``first``; ``tests/integration/
test_metrics_evo.py`` checks that against evo's own command line.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from albot1.geometry import se2
from albot1.metrics.alignment import ALIGNMENTS, Alignment, align, check_pair, describe
from albot1.metrics.errors import MetricsError
from albot1.metrics.stats import suffixed, summarize


def position_errors(
    estimate: ArrayLike, reference: ArrayLike, alignment: Alignment = "rigid", n_to_align: int | None = None
) -> np.ndarray:
    """Per-scan position error (m) after ``alignment`` (``n_to_align``: as for :func:`ate`).

    The numbers :func:`ate` summarises: the report's per-pose pictures and
    hover values (``albot1.report.interactive``) take them from here.
    """
    est, ref = check_pair(estimate, reference, "ATE")
    aligned, _ = align(est, ref, alignment, n_to_align)
    return np.hypot(aligned[:, 0] - ref[:, 0], aligned[:, 1] - ref[:, 1])


def ate(
    estimate: ArrayLike, reference: ArrayLike, alignment: Alignment = "rigid", n_to_align: int | None = None
) -> dict[str, Any]:
    """The ``ate`` block of ``metrics.json``.

    Holds ``rmse_m, mean_m, median_m, std_m, min_m, max_m, n`` of the position
    error, ``rotation`` (the same statistics of the heading error, ``_deg``),
    ``alignment`` (the method's name) and ``alignment_transform`` (the motion
    applied to the estimate), and ``other_alignments`` (rmse/mean/max under
    the two other alignments, so a reader sees how much the choice matters).
    ``n_to_align`` (rigid only): the alignment is estimated on the first N
    pairs (evo's ``--n_to_align``), named in ``alignment_transform``.
    """
    est, ref = check_pair(estimate, reference, "ATE")
    if len(est) == 1 and alignment != "none":
        # `NAME[:1]`, a dropout that kept one scan: the alignment puts the one pose on the reference's, so an
        # error of 0 m and 0 deg would be a made-up perfect score, not a measurement.
        raise MetricsError(
            f"ATE: one pose, which the {alignment} alignment puts exactly on the reference's (its error is 0 by "
            "construction); expected at least 2 poses"
        )
    aligned, transform = align(est, ref, alignment, n_to_align)
    trans = np.hypot(aligned[:, 0] - ref[:, 0], aligned[:, 1] - ref[:, 1])
    rot = np.degrees(np.abs(se2.wrap(aligned[:, 2] - ref[:, 2])))
    block: dict[str, Any] = {"alignment": alignment, "units": {"translation": "m", "rotation": "deg"}}
    block.update(suffixed(summarize(trans, ddof=0), "m"))
    block["rotation"] = suffixed(summarize(rot, ddof=0), "deg")
    block["alignment_transform"] = describe(transform, alignment, n_to_align)
    others: dict[str, Any] = {}
    for other in ALIGNMENTS:
        if other != alignment:
            s = summarize(position_errors(est, ref, other), ddof=0)  # type: ignore[arg-type]
            others[other] = {"rmse_m": s["rmse"], "mean_m": s["mean"], "max_m": s["max"]}
    block["other_alignments"] = others
    return block


#: Reference travel per window of :func:`windowed_ate`.
WINDOW_M = 50.0


def windowed_ate(
    estimate: ArrayLike, reference: ArrayLike, window_m: float = WINDOW_M, alignment: Alignment = "rigid"
) -> dict[str, Any]:
    """The ``ate_windows`` block: ATE of consecutive windows of ``window_m`` reference travel, each aligned alone.

    ``mean_rmse_m`` (the headline) is the mean of the windows' RMSE;
    ``window_rmse`` their full summary, ``per_window`` each window's scans,
    RMSE and maximum.

    One ATE over a whole long log is dominated by where the first large
    heading error happens (everything after it is rotated away from the
    reference); the mean over windows measures the accuracy a user of any
    50 m of the map sees, and is far less sensitive to one event. Window
    ``k`` holds the scans from the first at or beyond ``k * window_m`` of
    reference travel up to the first at or beyond ``(k + 1) * window_m``;
    the tail shorter than a window is left out (``uncovered_m``). A window
    that no scan falls in (one reference step longer than the window jumps
    over it: a gap in a sparse reference file) is left out and counted
    (``windows_without_scan``): it used to be scored on the one scan that
    ends it, which its own alignment puts on the reference exactly, an
    RMSE of 0 by construction pulling the mean down. At least two windows
    holding scans are needed (a MetricsError otherwise); ``windows`` counts
    those scored.
    """
    est, ref = check_pair(estimate, reference, "windowed ATE")
    if not window_m > 0:
        raise MetricsError(f"windowed ATE: expected a positive window length, got {window_m} m")
    travel = se2.cumulative_length(ref)
    total = float(travel[-1])
    count = int(np.floor(total / window_m + 1e-9))
    if count < 2:
        raise MetricsError(
            f"windowed ATE: the route ({total:.1f} m of reference travel) is shorter than two {window_m:g} m windows"
        )
    bounds = np.searchsorted(travel, np.arange(count + 1) * window_m - 1e-9, side="left")
    windows: list[dict[str, Any]] = []
    for k in range(count):
        first, last = int(bounds[k]), int(bounds[k + 1])
        if first == last:  # no scan in this window: its "error" would be one pose aligned onto itself
            continue
        s = summarize(position_errors(est[first : last + 1], ref[first : last + 1], alignment), ddof=0)
        windows.append({"first_scan": first, "last_scan": last, "rmse_m": s["rmse"], "max_m": s["max"]})
    if len(windows) < 2:
        raise MetricsError(
            f"windowed ATE: {len(windows)} of the route's {count} {window_m:g} m windows hold a scan (the reference "
            "steps over the others); expected at least two"
        )
    rmse = [w["rmse_m"] for w in windows]
    return {
        "alignment": f"{alignment}, each window on its own",
        "window_m": window_m,
        "windows": len(windows),
        "windows_without_scan": count - len(windows),
        "uncovered_m": total - count * window_m,
        "units": {"translation": "m"},
        "mean_rmse_m": float(np.mean(rmse)),
        "window_rmse": suffixed(summarize(rmse, ddof=0), "m"),
        "per_window": windows,
    }
