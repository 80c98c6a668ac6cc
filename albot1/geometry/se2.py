"""SE(2) poses ``(x, y, theta)``: one implementation, in a scalar and a vectorised form.

A pose ``a`` maps points from its own frame into the parent frame:
``p_parent = R(theta) @ p + (x, y)``. ``compose(a, b)`` is ``a * b`` (``b``
expressed in ``a``'s frame), ``between(a, b)`` is ``inv(a) * b``, the motion
from ``a`` to ``b`` seen from ``a``, which is what odometry increments and
ground-truth relations are. Angles are radians, counter-clockwise positive.

**Angle wrap convention** (every heading this package computes): an angle is
wrapped to ``[-pi, pi)`` by ``(a + pi) mod 2 pi - pi`` with the floored
(Python/numpy) modulo. The formula is not exact for an angle already in range
(``a + pi - pi`` can differ from ``a`` by one rounding, at most 4.4e-16 rad);
it is kept because every recorded result was computed with it.
:func:`wrap_angle` (scalar) and :func:`wrap` (vectorised) give the same bits.

Two forms of the same maths:

* **scalar** (:data:`Pose`, :func:`wrap_angle`, :func:`compose_pose`,
  :func:`between_pose`): single poses as plain floats, for the per-scan path
  of the mappers, where numpy's per-call overhead (tens of microseconds)
  would dominate the arithmetic. :func:`wrap_angle` is also compiled into the
  numba kernels, so it uses only Python scalars and :mod:`math`;
* **vectorised** (everything else): arrays of poses ``(..., 3)``, for whole
  trajectories (metrics, data preparation).

:func:`pose_to_se3` and :func:`pose_from_se3` bridge to 4x4 SE(3) matrices,
which 3-D registration libraries (KISS-ICP) work with.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from albot1.geometry.types import FloatArray

#: A single pose ``(x, y, theta)`` as plain floats (the scalar API).
Pose = tuple[float, float, float]
#: What the scalar API accepts: a :data:`Pose` or a length-3 array.
PoseLike = Pose | FloatArray


# -- scalar: single poses as plain floats -------------------------------------------------------------------------


def wrap_angle(a: float) -> float:
    """``a`` wrapped to ``[-pi, pi)`` (the module's convention; compiled into the numba kernels)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def compose_pose(a: PoseLike, b: PoseLike) -> Pose:
    """``a * b`` for single poses: pose ``b`` (given in ``a``'s frame) in ``a``'s parent frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap_angle(a[2] + b[2]))


def between_pose(a: PoseLike, b: PoseLike) -> Pose:
    """``inv(a) * b`` for single poses: the pose of ``b`` seen from ``a`` (e.g. an odometry increment)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return (c * dx + s * dy, -s * dx + c * dy, wrap_angle(b[2] - a[2]))


def rotate(theta: float, x: float, y: float) -> tuple[float, float]:
    """The point ``(x, y)`` rotated by ``theta`` about the origin: ``R(theta) @ (x, y)``."""
    c, s = math.cos(theta), math.sin(theta)
    return c * x - s * y, s * x + c * y


def rows_rotation(theta: float) -> FloatArray:
    """``R(theta).T``, the 2x2 matrix that rotates points stored as rows: ``points @ rows_rotation(theta)``.

    For clouds ``(k, 2)`` whose row-vector form is what the matrix product
    wants (one BLAS call per cloud rather than per coordinate).
    """
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, s], [-s, c]])


def pose_to_se3(pose: PoseLike) -> FloatArray:
    """A pose as the 4x4 homogeneous SE(3) matrix of the motion in the z = 0 plane."""
    x, y, theta = (float(v) for v in pose)
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0.0, x], [s, c, 0.0, y], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def pose_from_se3(matrix: FloatArray) -> tuple[FloatArray, float]:
    """Project a 4x4 SE(3) matrix to a pose; also return the out-of-plane part dropped.

    The dropped part is ``max(|z| in m, tilt of the z axis in rad)``: zero
    for an exactly planar motion. The heading is read by atan2, so it lies
    in ``[-pi, pi]`` without a wrap.
    """
    yaw = math.atan2(matrix[1, 0], matrix[0, 0])
    tilt = math.acos(min(1.0, max(-1.0, float(matrix[2, 2]))))
    return np.array([matrix[0, 3], matrix[1, 3], yaw]), max(abs(float(matrix[2, 3])), tilt)


# -- vectorised: arrays of poses (..., 3) -------------------------------------------------------------------------


def wrap(angle: ArrayLike) -> FloatArray:
    """Angles wrapped to ``[-pi, pi)``, elementwise the same bits as :func:`wrap_angle`."""
    a = np.asarray(angle, dtype=float)
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def as_poses(poses: ArrayLike) -> FloatArray:
    """A float array whose last axis has length 3, or ValueError."""
    p = np.asarray(poses, dtype=float)
    if p.shape[-1:] != (3,):
        raise ValueError(f"expected poses with a last axis of length 3 (x, y, theta), got shape {p.shape}")
    return p


def _one_pose_each(a: ArrayLike, b: ArrayLike) -> bool:
    """Whether ``a`` and ``b`` are each one float64 pose, shape ``(3,)``: the case of :func:`compose`'s fast path.

    Why a fast path: graph SLAM's per-scan code calls :func:`compose` and
    :func:`between` on single poses about 10 times a scan (a tenth of
    gtsam-graph's CPU on intel, nearly all of it numpy's per-call overhead on
    0-d arrays and ``np.stack``). The fast path does the same IEEE operations
    in the same order on numpy float64 scalars, with the same ``np.cos`` /
    ``np.sin`` (so the same bits wherever numpy runs; a unit test compares
    them), and builds the one result array at the end.
    """
    return (
        type(a) is np.ndarray
        and type(b) is np.ndarray
        and a.shape == (3,)
        and b.shape == (3,)
        and a.dtype == np.float64
        and b.dtype == np.float64
    )


def compose(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """``a * b``: pose ``b`` (given in ``a``'s frame) in ``a``'s parent frame (single poses: a fast path)."""
    if _one_pose_each(a, b):
        (ax, ay, at), (bx, by, bt) = a.tolist(), b.tolist()  # type: ignore[union-attr]
        c, s = np.cos(at), np.sin(at)
        t = at + bt
        return np.array([ax + c * bx - s * by, ay + s * bx + c * by, (t + np.pi) % (2.0 * np.pi) - np.pi])
    a, b = as_poses(a), as_poses(b)
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    x = a[..., 0] + c * b[..., 0] - s * b[..., 1]
    y = a[..., 1] + s * b[..., 0] + c * b[..., 1]
    return np.stack([x, y, wrap(a[..., 2] + b[..., 2])], axis=-1)


def inverse(a: ArrayLike) -> FloatArray:
    """``inv(a)``."""
    a = as_poses(a)
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    x = -c * a[..., 0] - s * a[..., 1]
    y = s * a[..., 0] - c * a[..., 1]
    return np.stack([x, y, wrap(-a[..., 2])], axis=-1)


def between(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """``inv(a) * b``: the pose of ``b`` seen from ``a`` (single poses: :func:`_one_pose_each`'s fast path)."""
    if _one_pose_each(a, b):
        (ax, ay, at), (bx, by, bt) = a.tolist(), b.tolist()  # type: ignore[union-attr]
        c, s = np.cos(at), np.sin(at)
        dx, dy = bx - ax, by - ay
        t = bt - at
        return np.array([c * dx + s * dy, -s * dx + c * dy, (t + np.pi) % (2.0 * np.pi) - np.pi])
    a, b = as_poses(a), as_poses(b)
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    return np.stack([c * dx + s * dy, -s * dx + c * dy, wrap(b[..., 2] - a[..., 2])], axis=-1)


def transform_points(pose: ArrayLike, points: ArrayLike) -> FloatArray:
    """Points ``(..., 2)`` from the frame of one ``pose`` into its parent frame."""
    p = as_poses(pose)
    pts = np.asarray(points, dtype=float)
    c, s = np.cos(p[2]), np.sin(p[2])
    out = np.empty_like(pts)
    out[..., 0] = p[0] + c * pts[..., 0] - s * pts[..., 1]
    out[..., 1] = p[1] + s * pts[..., 0] + c * pts[..., 1]
    return out


def to_matrix(pose: ArrayLike) -> FloatArray:
    """Homogeneous 3x3 matrices for poses ``(..., 3)``."""
    p = as_poses(pose)
    c, s = np.cos(p[..., 2]), np.sin(p[..., 2])
    m = np.zeros(p.shape[:-1] + (3, 3))
    m[..., 0, 0], m[..., 0, 1], m[..., 0, 2] = c, -s, p[..., 0]
    m[..., 1, 0], m[..., 1, 1], m[..., 1, 2] = s, c, p[..., 1]
    m[..., 2, 2] = 1.0
    return m


def from_matrix(m: ArrayLike) -> FloatArray:
    """Poses from homogeneous 3x3 matrices (the rotation block is read by atan2)."""
    mat = np.asarray(m, dtype=float)
    return np.stack([mat[..., 0, 2], mat[..., 1, 2], np.arctan2(mat[..., 1, 0], mat[..., 0, 0])], axis=-1)


def relative_steps(poses: ArrayLike) -> FloatArray:
    """The ``N-1`` increments ``between(poses[i-1], poses[i])`` of a trajectory."""
    p = as_poses(poses)
    return between(p[:-1], p[1:])


def integrate_steps(start: ArrayLike, steps: ArrayLike) -> FloatArray:
    """A trajectory of ``len(steps) + 1`` poses from a start pose and robot-frame increments.

    Exact SE(2), vectorised as cumulative sums rather than composing the steps
    one by one: the heading before each step is the start heading plus the
    turns so far (wrapped once, at the end), and each step's translation is
    rotated by that heading. This is the form the synthetic worlds' odometry
    has always been integrated with, so their recorded results keep their bits.
    """
    p0 = as_poses(start).reshape(3)
    s = as_poses(steps).reshape(-1, 3)
    heading = p0[2] + np.concatenate([[0.0], np.cumsum(s[:, 2])])
    before = heading[:-1]
    c, si = np.cos(before), np.sin(before)
    dx = c * s[:, 0] - si * s[:, 1]
    dy = si * s[:, 0] + c * s[:, 1]
    x = p0[0] + np.concatenate([[0.0], np.cumsum(dx)])
    y = p0[1] + np.concatenate([[0.0], np.cumsum(dy)])
    return np.column_stack([x, y, wrap(heading)])


def scale_motion(increment: ArrayLike, ratio: float) -> FloatArray:
    """The increment's constant twist followed for ``ratio`` times as long: ``exp(ratio * log(increment))``.

    A constant-velocity model that meets a different time step scales the
    motion in the Lie algebra, not the pose's components: a turning robot
    moves along an arc, so twice the time is ``increment * increment`` (the
    heading doubles and the translation bends with it), half of it is the
    increment's square root. In complex form the translation ``t`` becomes
    ``t * (exp(i r theta) - 1) / (exp(i theta) - 1)``, written with half-angle
    sines so that small turns lose no digits; a straight increment
    (``theta == 0``) scales its translation by ``ratio``. The heading is the
    wrapped increment's, so an increment turning by half a turn or more is
    read as the shorter turn the other way. ``ratio == 1`` returns the
    increment's values unchanged (no rounding).
    """
    x, y, theta = (float(v) for v in as_poses(increment).reshape(3))
    if ratio == 1.0:
        return np.array([x, y, theta])
    if theta == 0.0:
        return np.array([ratio * x, ratio * y, 0.0])
    gain = math.sin(0.5 * ratio * theta) / math.sin(0.5 * theta)
    turn = 0.5 * (ratio - 1.0) * theta
    c, s = math.cos(turn), math.sin(turn)
    return np.array([gain * (c * x - s * y), gain * (s * x + c * y), wrap_angle(ratio * theta)])


def unwrap_headings(poses: ArrayLike) -> FloatArray:
    """A copy of a trajectory ``(N, 3)`` with its headings unwrapped (continuous, no 2 pi jumps).

    What :func:`interpolate_unwrapped` blends; a caller that samples one
    trajectory many times unwraps it once here.
    """
    p = as_poses(poses).reshape(-1, 3).copy()
    p[:, 2] = np.unwrap(p[:, 2])
    return p


def interpolate_unwrapped(times: ArrayLike, unwrapped: ArrayLike, query: ArrayLike) -> FloatArray:
    """Poses at ``query`` times from a trajectory whose headings are already unwrapped.

    Linear in x, y and heading (``np.interp``), the heading wrapped after the
    blend. ``times`` must be non-decreasing; queries outside
    ``[times[0], times[-1]]`` take the nearest end pose (callers that must
    not extrapolate check first).
    """
    t = np.asarray(times, dtype=float)
    u = as_poses(unwrapped)
    q = np.asarray(query, dtype=float)
    out = np.stack([np.interp(q, t, u[:, 0]), np.interp(q, t, u[:, 1]), np.interp(q, t, u[:, 2])], axis=-1)
    out[..., 2] = wrap(out[..., 2])
    return out


def interpolate(times: ArrayLike, poses: ArrayLike, query: ArrayLike) -> FloatArray:
    """Poses at ``query`` times, linear in x, y and the unwrapped heading (see :func:`interpolate_unwrapped`)."""
    return interpolate_unwrapped(times, unwrap_headings(poses), query)


def cumulative_length(poses: ArrayLike) -> FloatArray:
    """Distance travelled up to each pose (0 at the first), metres."""
    p = as_poses(poses)
    return np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(p[:, 0]), np.diff(p[:, 1])))])


def path_length(poses: ArrayLike) -> float:
    """Total translation along a trajectory, metres."""
    p = as_poses(poses)
    if len(p) < 2:
        return 0.0
    return float(np.sum(np.hypot(np.diff(p[:, 0]), np.diff(p[:, 1]))))
