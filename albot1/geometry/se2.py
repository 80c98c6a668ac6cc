"""SE(2) poses as ``(x, y, theta)`` arrays, vectorised over leading axes.

A pose ``a`` maps points from its own frame into the parent frame:
``p_parent = R(theta) @ p + (x, y)``. ``compose(a, b)`` is ``a * b`` (``b``
expressed in ``a``'s frame), ``between(a, b)`` is ``inv(a) * b``, the motion
from ``a`` to ``b`` seen from ``a``, which is what odometry increments and
ground-truth relations are. Angles are radians, counter-clockwise positive.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def wrap(angle: ArrayLike) -> FloatArray:
    """Angles wrapped to ``[-pi, pi)``."""
    a = np.asarray(angle, dtype=float)
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def as_poses(poses: ArrayLike) -> FloatArray:
    """A float array whose last axis has length 3, or ValueError."""
    p = np.asarray(poses, dtype=float)
    if p.shape[-1:] != (3,):
        raise ValueError(f"expected poses with a last axis of length 3 (x, y, theta), got shape {p.shape}")
    return p


def compose(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """``a * b``: pose ``b`` (given in ``a``'s frame) expressed in ``a``'s parent frame."""
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
    """``inv(a) * b``: the pose of ``b`` seen from ``a``."""
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
    """A trajectory of ``len(steps) + 1`` poses from a start pose and increments."""
    start_pose = as_poses(start)
    increments = as_poses(steps)
    out = np.empty((len(increments) + 1, 3))
    out[0] = start_pose
    for i, step in enumerate(increments):
        out[i + 1] = compose(out[i], step)
    return out


def interpolate(times: ArrayLike, poses: ArrayLike, query: ArrayLike) -> FloatArray:
    """Poses at ``query`` times, linear in x, y and the unwrapped heading.

    ``times`` must be non-decreasing; queries outside ``[times[0], times[-1]]``
    take the nearest end pose (callers that must not extrapolate check first).
    """
    t = np.asarray(times, dtype=float)
    p = as_poses(poses)
    q = np.asarray(query, dtype=float)
    theta = np.unwrap(p[:, 2])
    out = np.stack([np.interp(q, t, p[:, 0]), np.interp(q, t, p[:, 1]), np.interp(q, t, theta)], axis=-1)
    out[..., 2] = wrap(out[..., 2])
    return out


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
