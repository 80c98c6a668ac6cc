"""2D scan registration: point-to-line ICP with an odometry prior.

Pure maths (numpy, scipy's cKDTree and a compiled grid search that gives
the tree's answers, :mod:`.nearest`), no I/O. A :class:`Target` is a point
set with one line normal per point (:func:`line_normals`: the principal axes
of its nearest neighbours); :func:`register` finds the SE(2) pose that maps source points
onto the target's local lines, Gauss-Newton with Cauchy weights, starting
from an initial guess and annealing the correspondence gate from
``max_correspondence_m`` down to ``min_correspondence_m``.

Why point-to-line rather than point-to-point: laser scans of buildings are
mostly walls; point-to-line converges in a handful of iterations and does not
pull scans along a wall by sampling differences (Censi 2008). Why a weak
prior on the initial guess: in a featureless corridor the along-corridor
direction has no gradient; the prior keeps that direction at the odometry
guess instead of letting a near-singular normal matrix send it anywhere, and
the returned information matrix says how much the match actually knows.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph import icp_loop
from albot1.methods.baselines.gtsam_graph.block_sums import MOMENT_NEIGHBOURS, line_moments
from albot1.methods.baselines.gtsam_graph.errors import RegistrationError
from albot1.methods.baselines.gtsam_graph.nearest import Grid, Matches, check_gate

if TYPE_CHECKING:
    from scipy.spatial import cKDTree


@dataclass(frozen=True)
class IcpParams:
    """Knobs of one registration (see :class:`~albot1.methods.baselines.gtsam_graph.config.GtsamGraphConfig`)."""

    max_iterations: int = 30
    max_correspondence_m: float = 1.0
    min_correspondence_m: float = 0.2
    point_sigma_m: float = 0.05
    cauchy_scale_m: float = 0.1
    prior_sigma_xy_m: float = 1.0
    prior_sigma_theta_rad: float = 0.2
    gate_decay: float = 0.7
    tolerance_m: float = 5e-4
    tolerance_rad: float = 1e-4
    #: a run that used every iteration still counts as converged if its last step was below this many tolerances
    settle_factor: float = 10.0
    min_points: int = 10


@dataclass(frozen=True)
class Registration:
    """The outcome of :func:`register`.

    ``pose`` maps source points into the target frame. ``fitness`` is the
    fraction of source points with a target line within the final gate,
    ``rmse_m`` the RMS point-to-line distance of those inliers, and
    ``information`` the 3x3 Gauss-Newton information of the scan terms alone
    (``J^T W J / point_sigma^2``, order x, y, theta), without the prior.
    """

    pose: FloatArray
    converged: bool
    iterations: int
    fitness: float
    rmse_m: float
    inliers: int
    information: FloatArray


def line_normals(
    points: FloatArray, neighbours: int = 6, radius_m: float = 0.5, max_planarity: float = 0.2
) -> tuple[FloatArray, FloatArray]:
    """The line-like points of ``points`` and one unit normal each.

    A point's normal is the minor principal axis of its ``neighbours``
    nearest points within ``radius_m``; points whose neighbourhood is not
    line-like (eigenvalue ratio above ``max_planarity``: clutter, isolated
    returns) are dropped because they would only add noise. Computed once per
    scan and rotated with it, so local maps are cheap to assemble.
    """
    from scipy.spatial import cKDTree

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    if not np.isfinite(pts).all():
        raise RegistrationError(f"target points must be finite; {int((~np.isfinite(pts)).any(axis=1).sum())} are not")
    if len(pts) < 3:
        return np.empty((0, 2)), np.empty((0, 2))
    k = min(neighbours, len(pts))
    dist, idx = cKDTree(pts).query(pts, k=k, distance_upper_bound=radius_m)
    if k <= MOMENT_NEIGHBOURS:
        counts = np.empty(len(pts), dtype=np.int64)
        cxx, cyy, cxy = np.empty(len(pts)), np.empty(len(pts)), np.empty(len(pts))
        line_moments(
            np.ascontiguousarray(pts), np.ascontiguousarray(dist), np.ascontiguousarray(idx, dtype=np.int64), counts,
            cxx, cyy, cxy,
        )  # fmt: skip
    else:  # the same sums through numpy (more neighbours than the kernel sums one after the other)
        ok = np.isfinite(dist)
        counts = ok.sum(axis=1)
        idx = np.where(ok, idx, np.arange(len(pts))[:, None])  # pad with the point itself, weight 0
        w = ok[..., None].astype(float)
        nb = pts[idx]
        mean = (nb * w).sum(axis=1) / np.maximum(counts, 1)[:, None]
        d = (nb - mean[:, None, :]) * w
        cxx = (d[..., 0] ** 2).sum(axis=1)
        cyy = (d[..., 1] ** 2).sum(axis=1)
        cxy = (d[..., 0] * d[..., 1]).sum(axis=1)
    root = np.sqrt((0.5 * (cxx - cyy)) ** 2 + cxy**2)
    lam_max = 0.5 * (cxx + cyy) + root
    lam_min = 0.5 * (cxx + cyy) - root
    axis = 0.5 * np.arctan2(2.0 * cxy, cxx - cyy)  # direction of the major axis
    keep = (counts >= 3) & (lam_max > 1e-12) & (lam_min <= max_planarity * np.maximum(lam_max, 1e-12))
    normals = np.column_stack([-np.sin(axis[keep]), np.cos(axis[keep])])
    return pts[keep], normals


def side_by_side(left: FloatArray, right: FloatArray) -> FloatArray:
    """``np.hstack([left, right])`` of two ``(n, 2)`` float64 arrays: the same bytes, copied a row pair at a time.

    numpy copies into a ``(n, 4)`` array's column pairs two values per inner
    loop (about 15 ns a value); seen as one complex128 per row, each side is
    one strided copy of ``n`` 16-byte items, a plain copy of the same bytes
    (no arithmetic), several times faster on a local map of 1,500 points.
    """
    out = np.empty((len(left), 4))
    pairs = out.view(np.complex128)
    pairs[:, 0] = np.ascontiguousarray(left).view(np.complex128)[:, 0]
    pairs[:, 1] = np.ascontiguousarray(right).view(np.complex128)[:, 0]
    return out


class Target:
    """Points with line normals (from :func:`line_normals`), indexed for matching.

    Two indexes, each built on first use: the grid of ICP's compiled
    correspondence search (:mod:`.nearest`), and scipy's k-d tree, which
    answers that search's ambiguous queries and every other caller.
    """

    def __init__(self, points: FloatArray, normals: FloatArray) -> None:
        self.points: FloatArray = np.asarray(points, dtype=float).reshape(-1, 2)
        self.normals: FloatArray = np.asarray(normals, dtype=float).reshape(-1, 2)
        if self.points.shape != self.normals.shape:
            raise RegistrationError(
                f"expected one normal per target point, got {len(self.normals)} for {len(self.points)}"
            )
        if not (np.isfinite(self.points).all() and np.isfinite(self.normals).all()):
            raise RegistrationError("target points and normals must be finite")
        # Each point beside its normal: one gather per ICP iteration fetches both (:func:`_linearise`).
        self.lines: FloatArray = side_by_side(self.points, self.normals)

    @functools.cached_property
    def tree(self) -> cKDTree | None:
        """scipy's k-d tree of the points (None when there are none)."""
        from scipy.spatial import cKDTree

        return cKDTree(self.points) if len(self.points) else None

    @functools.cached_property
    def grid(self) -> Grid:
        """The points in grid cells, for ICP's correspondences (:mod:`.nearest`); needs at least one point."""
        return Grid(self.points)

    @classmethod
    def from_points(
        cls, points: FloatArray, neighbours: int = 6, radius_m: float = 0.5, max_planarity: float = 0.2
    ) -> Target:
        """A target from raw points (normals estimated here)."""
        return cls(*line_normals(points, neighbours, radius_m, max_planarity))

    def __len__(self) -> int:
        return int(len(self.points))


def rotate(vectors: FloatArray, angle: float) -> FloatArray:
    """Row vectors ``(N, 2)`` (points or normals) rotated by ``angle`` rad: ``R v`` for each row.

    One matrix product rather than :func:`albot1.geometry.se2.transform_points`
    with a zero translation: the same maths, but BLAS rounds the products
    differently in the last bit, and every recorded gtsam-graph result was
    computed with this form.
    """
    c, s = math.cos(angle), math.sin(angle)
    rotated: FloatArray = vectors @ np.array([[c, s], [-s, c]])
    return rotated


def rotate_runs(parts: list[FloatArray], angles: list[float]) -> FloatArray:
    """``np.concatenate([rotate(v, a) for v, a in zip(parts, angles)])``: the same bits, in one compiled call.

    Where ICP's loop is compiled (:func:`.icp_loop.available`), every part of
    two rows or more is turned by :func:`.icp_loop.rotate_runs` with the
    dgemm numpy's matmul calls and CPython's ``cos`` and ``sin``; a single row
    is turned here by numpy, as before (its matmul branch differs). Saves
    numpy's per-call overhead on each node of a target (docs/baselines.md,
    "Cost (issue 24), fifth round").
    """
    vectors = np.ascontiguousarray(np.concatenate(parts), dtype=np.float64)
    if not icp_loop.available():
        return np.concatenate([rotate(v, a) for v, a in zip(parts, angles, strict=True)])
    counts = np.array([len(v) for v in parts], dtype=np.int64)
    out = np.empty_like(vectors)
    icp_loop.rotate_runs(vectors, np.array(angles, dtype=np.float64), counts, out)
    start = 0
    for v, a, n in zip(parts, angles, counts.tolist(), strict=True):
        if n == 1:
            out[start : start + 1] = rotate(v, a)
        start += n
    return out


def try_register(target: Target, points: FloatArray, guess: FloatArray, params: IcpParams) -> Registration | None:
    """:func:`register`, or None when either side has too few usable points to try (a miss, not an error)."""
    if len(points) < params.min_points or len(target) < params.min_points:
        return None
    return register(target, points, guess, params)


def register(target: Target, source: FloatArray, initial: FloatArray, params: IcpParams = IcpParams()) -> Registration:
    """Align ``source`` points (sensor frame) to ``target``, starting at ``initial``.

    Raises :class:`RegistrationError` for unusable input (non-finite values,
    too few points); a match that simply does not fit comes back with
    ``converged=False`` or a low ``fitness`` for the caller to judge.
    """
    src = np.ascontiguousarray(np.asarray(source, dtype=float).reshape(-1, 2))
    init = np.asarray(initial, dtype=float).reshape(3)
    if not np.isfinite(init).all():
        raise RegistrationError(f"initial guess must be finite, got {init.tolist()}")
    if not np.isfinite(src).all():
        raise RegistrationError(f"source points must be finite; {int((~np.isfinite(src)).any(axis=1).sum())} are not")
    if len(src) < params.min_points or len(target) < params.min_points or len(target) == 0:
        raise RegistrationError(
            f"need at least {params.min_points} source points and line-like target points, "
            f"got {len(src)} source and {len(target)} target"
        )

    matches = Matches(len(src))
    prior = _prior(params.prior_sigma_xy_m, params.prior_sigma_theta_rad)
    inv_var = params.point_sigma_m**-2
    if params.min_points >= 2 and icp_loop.available():  # numpy's matmul special-cases a single row or match
        (x, y, theta, iterations, converged, settled), (inliers, information, rmse) = _iterate_compiled(
            target, src, init, params, prior, matches
        )
        pose = np.array([x, y, theta])
    else:
        x, y, theta, iterations, converged, settled = _iterate(target, src, init, params, prior, matches)
        pose = np.array([x, y, theta])
        jac, res, _, wj = _linearise(
            target, src, pose, params.min_correspondence_m, params.cauchy_scale_m, inv_var, matches
        )
        inliers = int(len(res))
        information = wj.T @ jac if inliers else np.zeros((3, 3))
        rmse = float(np.sqrt(np.mean(res**2))) if inliers else float("inf")
    converged = converged or (settled and iterations == params.max_iterations)
    return Registration(
        pose=pose,
        converged=converged,
        iterations=iterations,
        fitness=inliers / len(src),
        rmse_m=rmse,
        inliers=inliers,
        information=information,
    )


@functools.lru_cache(maxsize=64)
def _prior(sigma_xy_m: float, sigma_theta_rad: float) -> FloatArray:
    """The odometry prior's information ``diag(sigma_xy^-2, sigma_xy^-2, sigma_theta^-2)``, built once per pair.

    Shared, so never written (ICP's loops only read it; a read-only flag
    would give numba another argument type, so none is set); cached because
    the tracker asks for the same few pairs thousands of times and ``np.diag``
    of a list costs more than the rest of a small registration's set-up.
    """
    return np.diag([sigma_xy_m**-2, sigma_xy_m**-2, sigma_theta_rad**-2])


#: what a Gauss-Newton loop leaves: the pose, the iterations run, whether it converged, whether its last step settled
Outcome = tuple[float, float, float, int, bool, bool]
#: the final terms' inlier count, information ``J^T W J`` and RMS residual (inf without inliers)
Final = tuple[int, FloatArray, float]


def _iterate_compiled(
    target: Target, src: FloatArray, init: FloatArray, params: IcpParams, prior: FloatArray, matches: Matches
) -> tuple[Outcome, Final]:
    """:func:`_iterate` and the final terms in one compiled call (:func:`.icp_loop.icp_run`), back here only for the
    k-d tree's answers.

    The same operations on the same data (numpy's own BLAS and LAPACK
    functions, CPython's ``cos``, ``sin``, ``remainder`` and ``hypot``), so the
    same bits; it saves the numpy calls' overhead around them, most of an
    iteration's CPU before (docs/baselines.md, "Cost (issue 24), fourth round"),
    and since the fifth round those of the final linearisation, ``wj.T @ jac``
    and the RMS too (one information from a single inlier is numpy's product here).
    """
    x0, y0, theta0 = init.tolist()
    knobs = np.array([
        params.max_iterations, params.min_correspondence_m, params.cauchy_scale_m, params.point_sigma_m**-2,
        params.gate_decay, params.tolerance_m, params.tolerance_rad, params.settle_factor, params.min_points,
        x0, y0, theta0,
    ], dtype=float)  # fmt: skip
    state = np.array([x0, y0, theta0, params.max_correspondence_m, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    grid, rot, scratch = target.grid, np.empty_like(src), np.zeros(icp_loop.SCRATCH)
    while True:
        status = icp_loop.icp_run(
            grid.origin, grid.dims, grid.cell, grid.starts, grid.xy, grid.order, target.lines, src, prior, knobs,
            state, matches.idx, matches.jac, matches.res, matches.w, matches.wj, rot, scratch,
        )  # fmt: skip
        if status != icp_loop.ASK_TREE:
            break
        matches.ask_tree(target.tree, rot, state[icp_loop.S_X : icp_loop.S_Y + 1], state[icp_loop.S_GATE])
        state[icp_loop.S_RESUME] = 1.0
    if status == icp_loop.BAD_GATE:
        check_gate(float(state[icp_loop.S_GATE]))
    x, y, theta, _, ran, settled, converged, _, _, found, rmse = state.tolist()
    inliers = int(found)
    if inliers >= 2:
        information = scratch[icp_loop.INFORMATION : icp_loop.INFORMATION + 9].reshape(3, 3).copy()
    else:
        information = matches.wj[:inliers].T @ matches.jac[:inliers] if inliers else np.zeros((3, 3))
    outcome = (x, y, theta, min(int(ran), params.max_iterations), bool(converged), bool(settled))
    return outcome, (inliers, information, rmse if inliers else float("inf"))


def _iterate(
    target: Target, src: FloatArray, init: FloatArray, params: IcpParams, prior: FloatArray, matches: Matches
) -> Outcome:
    """Gauss-Newton from ``init`` with the gate annealed, through numpy's calls (numba off, or another BLAS)."""
    inv_var = params.point_sigma_m**-2
    tau = 2.0 * math.pi
    pose = init.copy()
    gate = params.max_correspondence_m
    converged = False
    settled = False
    iterations = 0
    for iterations in range(1, params.max_iterations + 1):  # noqa: B007 -- read after the loop (the count run)
        jac, res, _, wj = _linearise(target, src, pose, gate, params.cauchy_scale_m, inv_var, matches)
        if len(res) < params.min_points:
            break
        offset = pose - init
        offset[2] = math.remainder(offset[2], tau)
        try:
            step = -np.linalg.solve(wj.T @ jac + prior, wj.T @ res + prior @ offset)
        except np.linalg.LinAlgError:
            break
        dx, dy, dtheta = step.tolist()
        if not (math.isfinite(dx) and math.isfinite(dy) and math.isfinite(dtheta)):
            break
        pose = pose + step
        pose[2] = math.remainder(pose[2], tau)
        moved, turned = math.hypot(dx, dy), abs(dtheta)
        small = moved < params.tolerance_m and turned < params.tolerance_rad
        if small and gate <= params.min_correspondence_m:
            converged = True
            break
        # Cauchy weights and nearest-neighbour switches can make the last digits cycle: a run that ends
        # within settle_factor tolerances of a fixed point is as good as converged.
        settled = (
            gate <= params.min_correspondence_m
            and moved < params.settle_factor * params.tolerance_m
            and turned < params.settle_factor * params.tolerance_rad
        )
        # Anneal the gate: wide while the guess may be far off, then down to the inlier gate.
        gate = max(params.min_correspondence_m, gate * params.gate_decay)
    x, y, theta = pose.tolist()
    return x, y, theta, iterations, converged, settled


def _linearise(
    target: Target,
    src: FloatArray,
    pose: FloatArray,
    gate: float,
    cauchy_scale: float,
    inv_var: float,
    matches: Matches | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Jacobian rows, point-to-line residuals, Cauchy weights and weighted rows (``jac * w * inv_var``) within ``gate``.

    Run once per ICP iteration (``matches``: the registration's buffers, see
    :class:`.nearest.Matches`). The correspondences are those of
    ``target.tree.query(moved, k=1, distance_upper_bound=gate)`` kept where
    ``dist < gate``, found by a compiled grid search that leaves to the k-d
    tree each query where the two could differ, and the terms are computed
    with the same operations in the same order as the numpy formulation every
    recorded result came from (:mod:`.nearest`; docs/baselines.md, "Cost,
    continued"): the same bits.
    """
    rot = rotate(src, pose[2])
    found = Matches(len(src)) if matches is None else matches
    return found.find(target.grid, lambda: target.tree, target.lines, rot, pose, gate, cauchy_scale, inv_var)
