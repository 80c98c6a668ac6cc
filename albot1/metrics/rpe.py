"""Relative pose error (RPE): drift over a fixed step, independent of alignment.

For pose pairs ``(i, j)`` the error is ``inv(inv(Q_i) Q_j) * inv(P_i) P_j``
(reference ``Q``, estimate ``P``; the TUM RGB-D definition evo uses): its
translation norm (m) and its absolute angle (deg). A rigid motion of the
whole estimate cancels in ``inv(P_i) P_j``, so the RPE needs no alignment.

Pairs are chosen the way evo does with consecutive (not all) pairs: by
index (``delta`` frames) or by travelled distance along the *reference*
(evo's ``--delta_unit m --pairs_from_reference``): a pair closes as soon as
the path accumulated since its first pose reaches ``delta`` metres. Using
the reference keeps the pairs identical for every method on a dataset.
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from albot1.geometry import se2
from albot1.metrics.alignment import check_pair
from albot1.metrics.errors import MetricsError
from albot1.metrics.stats import summarize

DeltaUnit = Literal["frames", "m"]

#: The steps reported by default: per scan, per metre and per 10 m of reference travel.
DEFAULT_DELTAS: tuple[tuple[float, DeltaUnit], ...] = ((1, "frames"), (1.0, "m"), (10.0, "m"))


def pair_indices(reference: ArrayLike, delta: float, unit: DeltaUnit) -> NDArray[np.int64]:
    """``(K, 2)`` consecutive index pairs ``delta`` frames or metres apart."""
    ref = np.asarray(reference, dtype=float)
    n = len(ref)
    if not (math.isfinite(delta) and delta > 0):
        # NaN and inf used to escape as ValueError / OverflowError (int(delta)) or give 0 pairs "of nan m"
        raise MetricsError(f"RPE: expected a positive finite delta, got {delta} {unit}")
    if unit == "frames":
        if int(delta) != delta:
            raise MetricsError(f"RPE: a delta in frames must be a whole number, got {delta}")
        ids = np.arange(0, n, int(delta))
    elif unit == "m":
        steps = np.hypot(np.diff(ref[:, 0]), np.diff(ref[:, 1]))
        picked = [0]
        travelled = 0.0
        # Sequential on purpose: the accumulator restarts at each picked pose (evo's rule).
        for i, step in enumerate(steps, start=1):
            travelled += float(step)
            if travelled >= delta:
                picked.append(i)
                travelled = 0.0
        ids = np.asarray(picked)
    else:
        raise MetricsError(f"RPE: unknown delta unit {unit!r}; expected 'frames' or 'm'")
    return np.column_stack([ids[:-1], ids[1:]]).astype(np.int64)


def relative_errors(estimate: ArrayLike, reference: ArrayLike, pairs: NDArray[np.int64]) -> NDArray[np.float64]:
    """``(K, 3)`` error poses ``inv(Q_ij) * P_ij`` for index pairs."""
    est, ref = check_pair(estimate, reference, "RPE")
    i, j = pairs[:, 0], pairs[:, 1]
    return se2.between(se2.between(ref[i], ref[j]), se2.between(est[i], est[j]))


def rpe(estimate: ArrayLike, reference: ArrayLike, delta: float = 1, unit: DeltaUnit = "frames") -> dict[str, Any]:
    """One RPE block: ``delta``, ``delta_unit``, ``pairs``, ``translation_m`` and ``rotation_deg`` statistics.

    No pair (a step longer than the trajectory, or a robot that never moves ``delta`` metres): null
    statistics and ``pairs_reason`` saying why (evo refuses such a delta; a block with one step too long
    for a short log keeps its other steps).
    """
    est, ref = check_pair(estimate, reference, "RPE")
    pairs = pair_indices(ref, delta, unit)
    err = relative_errors(est, ref, pairs)
    block: dict[str, Any] = {
        "delta": delta,
        "delta_unit": unit,
        "pairs": int(len(pairs)),
        "translation_m": summarize(np.hypot(err[:, 0], err[:, 1]), ddof=0),
        "rotation_deg": summarize(np.degrees(np.abs(err[:, 2])), ddof=0),
    }
    if len(pairs) == 0:
        block["pairs_reason"] = (
            f"{len(ref)} pose(s): none {delta:g} frames after another"
            if unit == "frames"
            else f"the reference travels {se2.path_length(ref):.3g} m in all, less than one step of {delta:g} m"
        )
    return block


def rpe_set(
    estimate: ArrayLike, reference: ArrayLike, deltas: tuple[tuple[float, DeltaUnit], ...] = DEFAULT_DELTAS
) -> dict[str, Any]:
    """The ``rpe`` block of ``metrics.json``: one entry per delta (the first is also at the top level)."""
    entries = [rpe(estimate, reference, d, u) for d, u in deltas]
    block: dict[str, Any] = {
        "alignment": "none (relative errors are invariant to a rigid motion of the estimate)",
        "pairs_from": "reference",
        "units": {"translation": "m", "rotation": "deg"},
    }
    block.update(entries[0])
    block["deltas"] = entries
    return block
