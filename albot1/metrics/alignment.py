"""SE(2) alignment of an estimated trajectory to a reference one.

Methods report poses in their own map frame, which differs from the
reference frame by an unknown rigid motion; absolute errors are meaningless
until that motion is removed, and *how* it is removed changes the numbers, so
every absolute metric names its alignment:

``none``
    compare the coordinates as they are (both already share a frame).
``first``
    move the estimate so its first pose equals the reference's first pose
    (evo's ``--align_origin``): errors then grow with the drift, which is
    what a robot that starts at a known pose experiences.
``rigid``
    the rotation and translation minimising the summed squared position
    error (Umeyama 1991 without scale, evo's ``--align``), in closed form for
    the plane: the rotation angle is ``atan2(sum cross, sum dot)`` of the
    centred positions, which is the 2-D case of the SVD solution and can
    never return a reflection. Positions on a line (a straight corridor, two
    poses) determine it too: unlike 3-D Umeyama (evo refuses them, "degenerate
    covariance rank") a rotation in the plane has no axis left free. Only
    when the positions cannot (one pose, or every position the same: a robot
    turning on the spot) is the rotation taken from the headings, the
    circular mean of their differences, among the equally good ones. Scale
    is never estimated: a metric map has no free scale. With ``n_to_align = N`` the motion is estimated on the
    first N pose pairs only and applied to all (evo's ``--align
    --n_to_align N``): the error then shows how far the run strays from
    where its beginning put it.
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike

from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.metrics.errors import MetricsError

Alignment = Literal["none", "first", "rigid"]
ALIGNMENTS: tuple[str, ...] = get_args(Alignment)


def check_poses(poses: ArrayLike, name: str, what: str) -> FloatArray:
    """``poses`` as an ``(N, 3)`` float array of finite poses, or MetricsError naming the first bad scan."""
    arr: FloatArray = np.asarray(poses, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise MetricsError(f"{what}: expected the {name} as (N, 3) poses (x, y, theta), got shape {arr.shape}")
    if not np.isfinite(arr).all():
        bad = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
        raise MetricsError(f"{what}: the {name} has a non-finite pose at scan {bad}")
    return arr


def check_pair(estimate: ArrayLike, reference: ArrayLike, what: str = "trajectories") -> tuple[FloatArray, FloatArray]:
    """Both as ``(N, 3)`` float arrays of equal length N >= 1, or MetricsError."""
    est = check_poses(estimate, "estimate", what)
    ref = check_poses(reference, "reference", what)
    if len(est) != len(ref):
        raise MetricsError(
            f"{what}: the estimate has {len(est)} poses and the reference {len(ref)}; expected one of each per scan"
        )
    if len(est) == 0:
        raise MetricsError(f"{what}: no poses to compare")
    return est, ref


def rigid_transform(estimate: ArrayLike, reference: ArrayLike) -> FloatArray:
    """The SE(2) pose ``T`` minimising ``sum |T * p_est - p_ref|^2`` over positions."""
    est, ref = check_pair(estimate, reference, "rigid alignment")
    p, q = est[:, :2], ref[:, :2]
    mp, mq = p.mean(axis=0), q.mean(axis=0)
    pc, qc = p - mp, q - mq
    dot = float(np.sum(pc[:, 0] * qc[:, 0] + pc[:, 1] * qc[:, 1]))
    cross = float(np.sum(pc[:, 0] * qc[:, 1] - pc[:, 1] * qc[:, 0]))
    if abs(dot) + abs(cross) > 1e-12:
        angle = float(np.arctan2(cross, dot))
    else:
        # One pose, or all positions equal (a robot turning on the spot): every angle gives the same position
        # error, so the positions do not determine the rotation. Of those equal optima take the one that best
        # matches the headings (their differences' circular mean); a fixed 0 would score a perfect estimate in
        # a rotated frame with the frames' angle as its heading error.
        turn = ref[:, 2] - est[:, 2]
        sin, cos = float(np.sum(np.sin(turn))), float(np.sum(np.cos(turn)))
        angle = float(np.arctan2(sin, cos)) if abs(sin) + abs(cos) > 1e-12 else 0.0
    c, s = np.cos(angle), np.sin(angle)
    t = mq - np.array([c * mp[0] - s * mp[1], s * mp[0] + c * mp[1]])
    return np.array([t[0], t[1], se2.wrap(angle)])


def alignment_transform(
    estimate: ArrayLike, reference: ArrayLike, method: Alignment, n_to_align: int | None = None
) -> FloatArray:
    """The pose ``T`` with which ``compose(T, estimate)`` is compared to the reference.

    ``n_to_align`` (``rigid`` only): estimate ``T`` on the first N pairs.
    """
    est, ref = check_pair(estimate, reference, f"{method} alignment")
    if n_to_align is not None:
        if method != "rigid" or n_to_align < 1:
            raise MetricsError(f"n_to_align={n_to_align} goes with the rigid alignment and a positive count")
        if n_to_align > len(est):
            # evo slices silently; the block would then name an N the alignment never used
            raise MetricsError(
                f"n_to_align={n_to_align}: the trajectories have {len(est)} pose pairs; expected at most {len(est)}"
            )
        return rigid_transform(est[:n_to_align], ref[:n_to_align])
    if method == "none":
        return np.zeros(3)
    if method == "first":
        return se2.compose(ref[0], se2.inverse(est[0]))
    if method == "rigid":
        return rigid_transform(est, ref)
    raise MetricsError(f"unknown alignment {method!r}; expected one of {', '.join(ALIGNMENTS)}")


def align(
    estimate: ArrayLike, reference: ArrayLike, method: Alignment, n_to_align: int | None = None
) -> tuple[FloatArray, FloatArray]:
    """``(aligned estimate, T)`` for one of :data:`ALIGNMENTS` (``n_to_align``: see :func:`alignment_transform`)."""
    transform = alignment_transform(estimate, reference, method, n_to_align)
    return se2.compose(transform, np.asarray(estimate, dtype=float)), transform


def describe(transform: ArrayLike, method: Alignment, n_to_align: int | None = None) -> dict[str, object]:
    """The JSON block naming an alignment and the motion it applied (m, deg); ``n_to_align`` only when set."""
    t = np.asarray(transform, dtype=float)
    block: dict[str, object] = {
        "method": method,
        "x_m": float(t[0]),
        "y_m": float(t[1]),
        "theta_deg": float(np.degrees(t[2])),
    }
    if n_to_align is not None:
        block["n_to_align"] = n_to_align
    return block
