"""The pose graph: GTSAM factors, ISAM2 online, Levenberg-Marquardt at the end.

Grisetti et al. (2010) separate the *front-end* (which edges exist, from
scan matching) from the *back-end* (the least-squares solve). This module is
the back-end only: nodes are integer keys 0..N-1 of ``Pose2`` variables,
edges are ``BetweenFactorPose2`` with full 3x3 covariances, loop edges carry
a robust kernel so that one wrong closure that passed the front-end's tests
is down-weighted instead of bending the whole map. ISAM2 keeps the estimate
current while the robot drives (the front-end needs it to search for loop
candidates); a final batch Levenberg-Marquardt over all factors removes what
ISAM2's partial relinearisation left behind.

Both solvers factor the whitened Jacobian by QR, not the Hessian by
Cholesky. Without loop closures the newest nodes' marginal uncertainty grows
without bound (heading drift times the lever arm of the path: on 500 nodes
of freiburg-campus one node's position sigma reaches ~110 m) while the edge
joining the two newest nodes stays centimetre-tight. The root clique of the
Bayes tree then holds an information block whose condition number
(1.3e8 after diagonal scaling) exceeds what GTSAM 4.3's Cholesky accepts
(1/sqrt(machine eps) = 6.7e7; it raises IndeterminantLinearSystemException).
Cholesky works on the square of the Jacobian's condition number, QR on the
number itself, so QR solves the same least-squares problem (the same
estimates to 1e-9 on Intel and ACES) where Cholesky gives up. No edge is
ill-conditioned (their covariances stay within condition number ~120), and
the anchor prior's stiffness is not the cause either: the gauge-free graph
is solved identically with a looser one, and it fails identically.

GTSAM is imported lazily, inside the class, so importing the package stays
cheap for the CLI.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph.errors import GraphError


def body_frame_covariance(relative: FloatArray, covariance: FloatArray) -> FloatArray:
    """Re-express a covariance of additive ``(x, y, theta)`` errors in GTSAM's Pose2 tangent frame.

    ICP perturbs the translation in the *parent* frame; GTSAM's between
    factor measures the error as ``Logmap(measured^-1 * predicted)``, whose
    translation part lives in the frame of the measured pose. To first order
    the two differ by the rotation of the measured pose.
    """
    c, s = np.cos(relative[2]), np.sin(relative[2])
    a = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    out: FloatArray = a @ np.asarray(covariance, dtype=float) @ a.T
    return 0.5 * (out + out.T)


class PoseGraph:
    """A growing 2D pose graph solved incrementally by ISAM2."""

    def __init__(self, relinearize_threshold: float = 0.01, factorization: Literal["QR", "CHOLESKY"] = "QR") -> None:
        """``factorization`` is QR for the reason in the module docstring; CHOLESKY is kept to demonstrate it."""
        import gtsam

        self._gtsam = gtsam
        self._factorization = factorization
        params = gtsam.ISAM2Params()
        params.setRelinearizeThreshold(relinearize_threshold)
        params.relinearizeSkip = 1
        params.setFactorization(factorization)
        self._isam = gtsam.ISAM2(params)
        self._all_factors = gtsam.NonlinearFactorGraph()
        self._new_factors = gtsam.NonlinearFactorGraph()
        self._new_values = gtsam.Values()
        self._size = 0
        self.optimisations = 0

    def __len__(self) -> int:
        return self._size

    def add_node(self, guess: FloatArray) -> int:
        """A new node at ``guess`` (its initial value); the first node is anchored with a tight prior."""
        gtsam = self._gtsam
        key = self._size
        self._new_values.insert(key, gtsam.Pose2(*map(float, guess)))
        if key == 0:
            noise = gtsam.noiseModel.Diagonal.Sigmas(np.array([1e-3, 1e-3, 1e-4]))
            self._add(gtsam.PriorFactorPose2(0, gtsam.Pose2(*map(float, guess)), noise))
        self._size += 1
        return key

    def add_edge(
        self,
        i: int,
        j: int,
        relative: FloatArray,
        covariance: FloatArray,
        kernel: Literal["cauchy", "huber", "none"] = "none",
        kernel_scale: float = 1.0,
    ) -> None:
        """A between edge ``x_i^-1 * x_j = relative`` with an additive-(x, y, theta) ``covariance``."""
        gtsam = self._gtsam
        rel = np.asarray(relative, dtype=float)
        cov = body_frame_covariance(rel, covariance)
        if not (np.isfinite(rel).all() and np.isfinite(cov).all()):
            raise GraphError(f"edge {i}->{j}: relative pose and covariance must be finite, got {rel.tolist()}")
        try:
            noise: Any = gtsam.noiseModel.Gaussian.Covariance(cov)
        except RuntimeError as exc:
            raise GraphError(f"edge {i}->{j}: covariance is not positive definite ({exc})") from exc
        if kernel == "cauchy":
            noise = gtsam.noiseModel.Robust.Create(gtsam.noiseModel.mEstimator.Cauchy.Create(kernel_scale), noise)
        elif kernel == "huber":
            noise = gtsam.noiseModel.Robust.Create(gtsam.noiseModel.mEstimator.Huber.Create(kernel_scale), noise)
        self._add(gtsam.BetweenFactorPose2(i, j, gtsam.Pose2(*map(float, rel)), noise))

    def _add(self, factor: Any) -> None:
        self._new_factors.add(factor)
        self._all_factors.add(factor)

    def update(self, extra_iterations: int = 0) -> None:
        """Hand new factors and values to ISAM2 (plus ``extra_iterations`` relinearisation passes)."""
        try:
            self._isam.update(self._new_factors, self._new_values)
            for _ in range(extra_iterations):
                self._isam.update()
        except RuntimeError as exc:  # gtsam raises IndeterminantLinearSystemException etc. as RuntimeError
            raise GraphError(f"ISAM2 update with {self._size} nodes failed: {exc}") from exc
        self._new_factors = self._gtsam.NonlinearFactorGraph()
        self._new_values = self._gtsam.Values()
        self.optimisations += 1

    def estimate(self, key: int) -> FloatArray:
        """The current ISAM2 estimate of one node."""
        p = self._isam.calculateEstimatePose2(key)
        return np.array([p.x(), p.y(), p.theta()])

    def estimate_rows(self, keys: range) -> FloatArray:
        """:meth:`estimate` of each of ``keys``, as the rows of one array (the same values, one array built)."""
        rows = []
        for key in keys:
            p = self._isam.calculateEstimatePose2(key)
            rows.append((p.x(), p.y(), p.theta()))
        return np.array(rows, dtype=np.float64).reshape(-1, 3)

    def estimates(self) -> FloatArray:
        """The current ISAM2 estimates of all nodes, ``(N, 3)`` in key order."""
        if self._size == 0:
            return np.empty((0, 3))
        return self._poses(self._isam.calculateEstimate())

    def optimise(self, max_iterations: int = 100) -> FloatArray:
        """Batch Levenberg-Marquardt over every factor, started from the ISAM2 estimate."""
        gtsam = self._gtsam
        if self._new_factors.size() or self._new_values.size():
            self.update()
        if self._size == 0:
            return np.empty((0, 3))
        params = gtsam.LevenbergMarquardtParams()
        params.setMaxIterations(max_iterations)
        params.setLinearSolverType("MULTIFRONTAL_QR" if self._factorization == "QR" else "MULTIFRONTAL_CHOLESKY")
        try:
            result = gtsam.LevenbergMarquardtOptimizer(
                self._all_factors, self._isam.calculateEstimate(), params
            ).optimize()
        except RuntimeError as exc:
            raise GraphError(f"Levenberg-Marquardt over {self._size} nodes failed: {exc}") from exc
        self.optimisations += 1
        poses = self._poses(result)
        if not np.isfinite(poses).all():
            raise GraphError(f"Levenberg-Marquardt over {self._size} nodes returned non-finite poses (diverged)")
        return poses

    def _poses(self, values: Any) -> FloatArray:
        poses = np.asarray(self._gtsam.utilities.extractPose2(values), dtype=float).reshape(-1, 3)
        if len(poses) != self._size:
            raise GraphError(f"expected {self._size} node poses from GTSAM, got {len(poses)}")
        return poses
