"""Relative pose error per travelled distance ("drift per 10 m"), over every start point.

The evo-style RPE of :mod:`albot1.metrics.rpe` takes *consecutive* pairs
``delta`` metres apart: on a 500 m log that is 50 pairs at 10 m, and which
50 depends on where the first one starts. Here, as in the KITTI odometry
benchmark, a segment starts at every metre of reference travel (the first
scan at or beyond each multiple of ``start_spacing_m``) and ends at the
first scan whose reference travel since the start reaches ``length_m``
(within :data:`SLACK`). Each segment's error is ``inv(Q_ij) * P_ij``
(reference ``Q``, estimate ``P``), reported as its translation norm (m)
and absolute angle (deg), for a sweep of segment lengths. Starting points
are spaced by travel, not by scan, so a robot standing still does not
weigh more than one moving; they come from the reference, so every method
is scored on the same segments. Relative errors need no alignment.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from albot1.geometry import se2
from albot1.metrics.alignment import check_pair
from albot1.metrics.errors import MetricsError
from albot1.metrics.stats import summarize

#: Segment lengths (m) of the sweep; the headline is :data:`HEADLINE_M`.
DEFAULT_LENGTHS_M: tuple[float, ...] = (1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0)
HEADLINE_M = 10.0
#: A segment starts at the first scan at or beyond every multiple of this much reference travel.
START_SPACING_M = 1.0
#: So that ten 0.1 m steps summed in floating point reach 1 m.
SLACK = 1e-9


def segment_pairs(reference: ArrayLike, length_m: float, start_spacing_m: float = START_SPACING_M) -> NDArray[np.int64]:
    """``(K, 2)`` scan index pairs: a start every ``start_spacing_m`` of travel, its end ``length_m`` further."""
    if not (length_m > 0 and start_spacing_m > 0):
        raise MetricsError(f"drift: expected positive lengths, got segment {length_m} m, spacing {start_spacing_m} m")
    travel = se2.cumulative_length(reference)
    total = float(travel[-1]) if len(travel) else 0.0
    marks = np.arange(0.0, total + SLACK, start_spacing_m)
    starts = np.unique(np.searchsorted(travel, marks - SLACK, side="left"))
    starts = starts[starts < len(travel)]
    ends = np.searchsorted(travel, travel[starts] + length_m - SLACK, side="left")
    ok = ends < len(travel)
    return np.column_stack([starts[ok], ends[ok]]).astype(np.int64)


def segment_errors(estimate: ArrayLike, reference: ArrayLike, pairs: NDArray[np.int64]) -> NDArray[np.float64]:
    """``(K, 2)``: translation error (m) and absolute rotation error (deg) of each segment."""
    est, ref = check_pair(estimate, reference, "drift")
    i, j = pairs[:, 0], pairs[:, 1]
    err = se2.between(se2.between(ref[i], ref[j]), se2.between(est[i], est[j])).reshape(-1, 3)
    return np.column_stack([np.hypot(err[:, 0], err[:, 1]), np.degrees(np.abs(err[:, 2]))])


def drift(
    estimate: ArrayLike,
    reference: ArrayLike,
    lengths_m: tuple[float, ...] = DEFAULT_LENGTHS_M,
    start_spacing_m: float = START_SPACING_M,
) -> dict[str, Any]:
    """The ``drift`` block of ``metrics.json``.

    ``sweep``: one entry per segment length the route is long enough for
    (``length_m``, ``pairs``, ``translation_m`` and ``rotation_deg``
    statistics); ``lengths_beyond_route_m`` lists the others. ``at_10m``
    holds the means at 10 m (the headline: ``translation_m``,
    ``rotation_deg``, ``pairs``), or is null with ``at_10m_reason`` when the
    route is shorter.
    """
    est, ref = check_pair(estimate, reference, "drift")
    route_m = se2.path_length(ref)
    block: dict[str, Any] = {
        "alignment": "none (relative errors are invariant to a rigid motion of the estimate)",
        "pairs_from": "reference",
        "start_spacing_m": start_spacing_m,
        "route_m": route_m,
        "units": {"translation": "m", "rotation": "deg"},
    }
    sweep: list[dict[str, Any]] = []
    beyond: list[float] = []
    for length in lengths_m:
        pairs = segment_pairs(ref, length, start_spacing_m)
        if len(pairs) == 0:
            beyond.append(length)
            continue
        err = segment_errors(est, ref, pairs)
        sweep.append(
            {
                "length_m": length,
                "pairs": int(len(pairs)),
                "translation_m": summarize(err[:, 0], ddof=0),
                "rotation_deg": summarize(err[:, 1], ddof=0),
            }
        )
    block["sweep"] = sweep
    block["lengths_beyond_route_m"] = beyond
    pairs = segment_pairs(ref, HEADLINE_M, start_spacing_m)
    if len(pairs) == 0:
        block["at_10m"] = None
        block["at_10m_reason"] = f"the route ({route_m:.1f} m of reference travel) has no {HEADLINE_M:g} m segment"
    else:
        err = segment_errors(est, ref, pairs)
        block["at_10m"] = {
            "translation_m": float(err[:, 0].mean()),
            "rotation_deg": float(err[:, 1].mean()),
            "pairs": int(len(pairs)),
        }
    return block
