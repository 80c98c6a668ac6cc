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
from albot1.metrics.stats import suffixed, summarize


def position_errors(estimate: ArrayLike, reference: ArrayLike, alignment: Alignment = "rigid") -> np.ndarray:
    """Per-scan position error (m) after ``alignment``."""
    est, ref = check_pair(estimate, reference, "ATE")
    aligned, _ = align(est, ref, alignment)
    return np.hypot(aligned[:, 0] - ref[:, 0], aligned[:, 1] - ref[:, 1])


def ate(estimate: ArrayLike, reference: ArrayLike, alignment: Alignment = "rigid") -> dict[str, Any]:
    """The ``ate`` block of ``metrics.json``.

    Holds ``rmse_m, mean_m, median_m, std_m, min_m, max_m, n`` of the position
    error, ``rotation`` (the same statistics of the heading error, ``_deg``),
    ``alignment`` (the method's name) and ``alignment_transform`` (the motion
    applied to the estimate), and ``other_alignments`` (rmse/mean/max under
    the two other alignments, so a reader sees how much the choice matters).
    """
    est, ref = check_pair(estimate, reference, "ATE")
    aligned, transform = align(est, ref, alignment)
    trans = np.hypot(aligned[:, 0] - ref[:, 0], aligned[:, 1] - ref[:, 1])
    rot = np.degrees(np.abs(se2.wrap(aligned[:, 2] - ref[:, 2])))
    block: dict[str, Any] = {"alignment": alignment, "units": {"translation": "m", "rotation": "deg"}}
    block.update(suffixed(summarize(trans, ddof=0), "m"))
    block["rotation"] = suffixed(summarize(rot, ddof=0), "deg")
    block["alignment_transform"] = describe(transform, alignment)
    others: dict[str, Any] = {}
    for other in ALIGNMENTS:
        if other != alignment:
            s = summarize(position_errors(est, ref, other), ddof=0)  # type: ignore[arg-type]
            others[other] = {"rmse_m": s["rmse"], "mean_m": s["mean"], "max_m": s["max"]}
    block["other_alignments"] = others
    return block
