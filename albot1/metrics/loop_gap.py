"""Loop gap: how far apart a method puts two visits of the same place.

The thesis's Experiment 3 measures the "resultant distance error" between
two mapped positions of one physical corner (odometry 4.6 m, Albot1 0.4 m).
Two forms, both alignment-free (they compare relative poses):

``route``
    start vs end of the route: the error of the estimated end pose seen
    from the start pose, ``|trans(inv(P_0) P_N) - trans(inv(Q_0) Q_N)|``.
    For a route that returns to its start (``Q_N = Q_0``) this is the
    estimated end-to-start distance, exactly the thesis's measure; without a
    reference it can only be reported when the route is *known* to be
    closed (then the reference offset is zero by definition).
``pairs``
    every revisit: pairs of scans whose reference positions lie within
    :data:`RADIUS_M` of each other although more than :data:`MIN_DT_S`
    seconds and :data:`MIN_TRAVEL_M` metres of reference path apart (the
    travel bound keeps a robot standing still from counting as a loop; the
    time bound matches the relation metric's loop relations). Two scans
    that share a stamp are not held to the time bound: the log gives them no
    time to judge by (the corrected Radish logs belgioioso, freiburg-campus
    and orebro stamp every scan 0, csail and infinite-corridor nearly all one
    value), so the travel bound alone decides, and the block counts them
    (``pairs_same_stamp``). They used to fail it (a difference of 0 s), and
    those logs read "pairs: 0" though their routes revisit places (belgioioso
    12 pairs, orebro 11, csail 59 instead of 12). For each later
    scan only its nearest qualifying earlier scan is kept, so a revisited
    corridor contributes one pair per scan, not a quadratic number.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from albot1.geometry import se2
from albot1.metrics.alignment import check_pair, check_poses
from albot1.metrics.errors import MetricsError
from albot1.metrics.rpe import relative_errors
from albot1.metrics.stats import summarize

RADIUS_M = 0.5
MIN_DT_S = 30.0
MIN_TRAVEL_M = 10.0


def route_gap(estimate: ArrayLike, reference: ArrayLike | None = None) -> dict[str, Any]:
    """Start-to-end error (m, deg); with ``reference=None`` the route is taken as closed."""
    est = check_poses(estimate, "estimate", "loop gap")
    if len(est) < 2:
        # said "expected at least 2 poses (N, 3), got shape (1, 3)": a one-scan run read as an array of the wrong shape
        raise MetricsError(
            f"loop gap: {len(est)} pose(s), so no route from a start to an end; expected at least 2 poses"
        )
    d_est = se2.between(est[0], est[-1])
    if reference is None:
        d_ref = np.zeros(3)
    else:
        _, ref = check_pair(est, reference, "loop gap")
        d_ref = se2.between(ref[0], ref[-1])
    err = se2.between(d_ref, d_est)
    return {
        "estimated_offset_m": float(np.hypot(d_est[0], d_est[1])),
        "reference_offset_m": float(np.hypot(d_ref[0], d_ref[1])),
        "reference": "reference poses" if reference is not None else "closed route (end = start by definition)",
        "gap_m": float(np.hypot(err[0], err[1])),
        "heading_gap_deg": float(np.degrees(abs(err[2]))),
    }


def loop_pairs(
    timestamps: ArrayLike,
    reference: ArrayLike,
    *,
    radius_m: float = RADIUS_M,
    min_dt_s: float = MIN_DT_S,
    min_travel_m: float = MIN_TRAVEL_M,
) -> NDArray[np.int64]:
    """``(K, 2)`` pairs ``(i, j)``, ``i < j``: revisits by the rule in the module docstring."""
    from scipy.spatial import cKDTree

    t = np.asarray(timestamps, dtype=float)
    ref = np.asarray(reference, dtype=float)
    if len(t) != len(ref):
        raise MetricsError(f"loop pairs: {len(t)} timestamps but {len(ref)} reference poses")
    if len(ref) < 2:
        return np.empty((0, 2), dtype=np.int64)
    travel = se2.cumulative_length(ref)
    pairs = cKDTree(ref[:, :2]).query_pairs(radius_m, output_type="ndarray")
    if len(pairs) == 0:
        return np.empty((0, 2), dtype=np.int64)
    pairs = np.sort(pairs, axis=1)
    i, j = pairs[:, 0], pairs[:, 1]
    # a shared stamp says nothing of the time between two scans metres apart: only the travel bound applies
    keep = ((np.abs(t[j] - t[i]) > min_dt_s) | (t[j] == t[i])) & (travel[j] - travel[i] > min_travel_m)
    i, j = i[keep], j[keep]
    if len(i) == 0:
        return np.empty((0, 2), dtype=np.int64)
    dist = np.hypot(ref[i, 0] - ref[j, 0], ref[i, 1] - ref[j, 1])
    # Nearest partner per later scan j (ties: the earlier i), deterministic.
    order = np.lexsort((i, dist, j))
    i, j = i[order], j[order]
    first = np.concatenate([[True], j[1:] != j[:-1]])
    return np.column_stack([i[first], j[first]]).astype(np.int64)


def pair_gaps(timestamps: ArrayLike, estimate: ArrayLike, reference: ArrayLike, **rule: float) -> dict[str, Any]:
    """Errors of the estimated relative pose over every revisit pair (m, deg)."""
    est, ref = check_pair(estimate, reference, "loop pairs")
    t = np.asarray(timestamps, dtype=float)
    pairs = loop_pairs(t, ref, **rule)
    block: dict[str, Any] = {
        "radius_m": rule.get("radius_m", RADIUS_M),
        "min_dt_s": rule.get("min_dt_s", MIN_DT_S),
        "min_travel_m": rule.get("min_travel_m", MIN_TRAVEL_M),
        "pairs": int(len(pairs)),
        "pairs_same_stamp": int(np.count_nonzero(t[pairs[:, 0]] == t[pairs[:, 1]])),
    }
    if len(pairs) == 0:
        block.update({"translation_m": None, "rotation_deg": None, "worst_pair": None})
        return block
    i, j = pairs[:, 0], pairs[:, 1]
    err = relative_errors(est, ref, pairs)
    trans = np.hypot(err[:, 0], err[:, 1])
    worst = int(np.argmax(trans))
    block["translation_m"] = summarize(trans)
    block["rotation_deg"] = summarize(np.degrees(np.abs(err[:, 2])))
    block["worst_pair"] = {"scans": [int(i[worst]), int(j[worst])], "gap_m": float(trans[worst])}
    return block
