"""A long open chain: GTSAM's Cholesky refuses it, the QR back-end solves it exactly.

This reproduces, on a small synthetic graph, the failure seen on
freiburg-campus-corrected[:1000] (scan 583, 506 nodes, no loop closure):
every edge is well conditioned, but the newest nodes' marginal uncertainty
(heading variance times the lever arm of the path) grows with the cube of
the chain length while the edge between the two newest nodes stays tight.
Once the root clique's diagonally scaled information exceeds condition
number 1/sqrt(eps), GTSAM's Cholesky raises IndeterminantLinearSystemException.
"""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from albot1.methods.baselines.gtsam_graph.errors import GraphError
from albot1.methods.baselines.gtsam_graph.graph import PoseGraph

# Found, not imported, at collection (the tests import gtsam when they run).
pytestmark = pytest.mark.skipif(importlib.util.find_spec("gtsam") is None, reason="gtsam is not installed")

NODES = 300
STEP = np.array([1.0, 0.0, 0.0])
# 2 cm and 0.1 rad: the translation floor of a match and a loose heading (odometry fallbacks are looser still).
EDGE_COV = np.diag([4e-4, 4e-4, 1e-2])
GTSAM_MAX_CONDITION = 1.0 / np.sqrt(np.finfo(float).eps)  # what GTSAM's choleskyPartial accepts (6.7e7)


def drive(graph: PoseGraph, nodes: int = NODES) -> None:
    """A straight chain of 1 m steps, updated after every node as the mapper does."""
    graph.add_node(np.zeros(3))
    graph.update()
    for k in range(1, nodes):
        graph.add_node(k * STEP)
        graph.add_edge(k - 1, k, STEP, EDGE_COV)
        graph.update()


def newest_pair_condition(nodes: int) -> float:
    """Condition number of the two newest nodes' marginal information after diagonal scaling.

    Built from the exact linearisation of the straight chain at the truth,
    in GTSAM's Pose2 tangent convention (translation in the body frame):
    the between error of x_i -> x_j has Jacobian -Ad(T_j^-1 T_i) for x_i and
    the identity for x_j.
    """
    info = np.linalg.inv(EDGE_COV)
    h = np.zeros((3 * nodes, 3 * nodes))
    h[:3, :3] += np.diag([1e6, 1e6, 1e8])  # the anchor prior of node 0
    adjoint = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, STEP[0]], [0.0, 0.0, 1.0]])  # Ad(T_j^-1 T_i) for a 1 m step
    blocks = [(-adjoint, slice(0, 3)), (np.eye(3), slice(3, 6))]
    for k in range(1, nodes):
        base = 3 * (k - 1)
        for a, rows in blocks:
            for b, cols in blocks:
                h[base + rows.start : base + rows.stop, base + cols.start : base + cols.stop] += a.T @ info @ b
    marginal_info = np.linalg.inv(np.linalg.inv(h)[-6:, -6:])
    scale = 1.0 / np.sqrt(np.diag(marginal_info))
    return float(np.linalg.cond(marginal_info * scale[:, None] * scale[None, :]))


def test_every_edge_is_well_conditioned_but_the_chain_is_not() -> None:
    """Edges have condition 25; the newest nodes' information reaches 20x GTSAM's limit (it grows ~ N^3)."""
    assert np.linalg.cond(EDGE_COV) == pytest.approx(25.0)
    long, short = newest_pair_condition(NODES), newest_pair_condition(NODES // 3)
    assert long > 10 * GTSAM_MAX_CONDITION
    assert 20 < long / short < 30  # (300 / 100)^3 = 27


def test_cholesky_back_end_refuses_the_long_chain_only() -> None:
    short = PoseGraph(factorization="CHOLESKY")
    drive(short, NODES // 3)
    np.testing.assert_allclose(short.estimates(), np.arange(NODES // 3)[:, None] * STEP, atol=1e-6)
    with pytest.raises(GraphError, match="Indeterminate"):
        drive(PoseGraph(factorization="CHOLESKY"))


def test_qr_back_end_solves_the_long_chain_exactly() -> None:
    graph = PoseGraph()
    drive(graph)
    truth = np.arange(NODES)[:, None] * STEP
    np.testing.assert_allclose(graph.estimates(), truth, atol=1e-6)
    np.testing.assert_allclose(graph.optimise(), truth, atol=1e-6)
