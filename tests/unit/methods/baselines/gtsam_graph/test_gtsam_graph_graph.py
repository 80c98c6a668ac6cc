"""The GTSAM back-end: exact solutions of tiny graphs, robust loop edges, refused bad edges."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph.errors import GraphError
from albot1.methods.baselines.gtsam_graph.graph import PoseGraph, body_frame_covariance

# Found, not imported, at collection (the tests import gtsam when they run).
pytestmark = pytest.mark.skipif(importlib.util.find_spec("gtsam") is None, reason="gtsam is not installed")

COV = np.diag([0.01, 0.01, 0.001])


def square(graph: PoseGraph, noisy: bool) -> np.ndarray:
    """A 1 m square driven as 4 edges of (1 m, 90 deg): node 4 is back on node 0."""
    truth = se2.integrate_steps(np.zeros(3), np.tile([1.0, 0.0, math.pi / 2], (4, 1)))
    graph.add_node(truth[0])
    for i in range(1, 5):
        step = se2.between(truth[i - 1], truth[i])
        guess = truth[i] + (np.array([0.3, -0.2, 0.1]) if noisy else 0.0)
        graph.add_node(guess)
        graph.add_edge(i - 1, i, step, COV)
        graph.update()
    return truth


def assert_poses_close(a: np.ndarray, b: np.ndarray, atol: float) -> None:
    np.testing.assert_allclose(se2.between(a, b), np.zeros_like(a), atol=atol)


def test_chain_is_solved_exactly_by_isam2_and_lm() -> None:
    graph = PoseGraph()
    truth = square(graph, noisy=True)
    assert_poses_close(graph.estimates(), truth, atol=1e-6)
    assert_poses_close(graph.optimise(), truth, atol=1e-6)
    assert graph.optimisations == 4 + 1


def test_loop_edge_spreads_a_consistent_correction() -> None:
    graph = PoseGraph()
    truth = square(graph, noisy=False)
    # The last node is measured to be 0.4 m off the first: the correction is shared along the loop.
    graph.add_edge(0, 4, np.array([0.4, 0.0, 0.0]), COV)
    graph.update(extra_iterations=2)
    poses = graph.optimise()
    assert 0.05 < poses[4, 0] < 0.35
    assert abs(poses[0, 0]) < 1e-2
    _ = truth


def test_robust_kernel_limits_a_wrong_loop_edge() -> None:
    """A 5 m wrong closure moves the map far less under a Cauchy kernel than under a plain Gaussian."""
    shifts = {}
    for kernel in ("none", "cauchy"):
        graph = PoseGraph()
        truth = square(graph, noisy=False)
        graph.add_edge(0, 2, np.array([5.0, 0.0, 0.0]), COV, kernel=kernel, kernel_scale=1.0)
        graph.update()
        shifts[kernel] = float(np.abs(graph.optimise() - truth)[:, :2].max())
    assert shifts["cauchy"] < 0.25 * shifts["none"]


def test_body_frame_covariance_rotates_translation_block() -> None:
    cov = np.diag([0.04, 0.01, 0.001])
    out = body_frame_covariance(np.array([1.0, 2.0, math.pi / 2]), cov)
    np.testing.assert_allclose(out, np.diag([0.01, 0.04, 0.001]), atol=1e-12)


def test_non_finite_edge_is_refused() -> None:
    graph = PoseGraph()
    graph.add_node(np.zeros(3))
    graph.add_node(np.ones(3))
    with pytest.raises(GraphError, match="edge 0->1"):
        graph.add_edge(0, 1, np.array([np.nan, 0.0, 0.0]), COV)
