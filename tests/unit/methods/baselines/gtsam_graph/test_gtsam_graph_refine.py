"""Per-scan seeds between graph nodes (albot1.methods.baselines.gtsam_graph.refine), exact cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph.refine import RefineTests, accept, progress, seed_poses


def test_progress_counts_distance_and_rotation_as_magnitudes() -> None:
    steps = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    offsets = np.array([[0.25, 0.0, 0.0], [-0.5, 0.0, 0.0], [0.0, 0.0, -0.5], [0.3, 0.0, 0.0]])
    np.testing.assert_allclose(progress(offsets, steps), [0.25, 0.5, 0.5, 0.0])
    assert progress(np.array([[3.0, 0.0, 0.0]]), np.array([[1.0, 0.0, 0.0]]))[0] == 1.0


def test_seed_spreads_the_disagreement_with_the_next_node_along_the_segment() -> None:
    # The front-end measured node 1 at 1 m straight ahead, the optimiser put it at 1.2 m and 0.1 rad.
    nodes = np.array([[0.0, 0.0, 0.0], [1.2, 0.0, 0.1]])
    steps = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    scan_node = np.array([0, 0, 0, 1, 1])
    offsets = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.3, 0.0, 0.0]])
    seeds = seed_poses(nodes, steps, scan_node, offsets)
    np.testing.assert_allclose(seeds[0], [0.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(seeds[2], nodes[1], atol=1e-12)  # the end of the segment is the next node
    np.testing.assert_allclose(seeds[1], se2.compose([0.5, 0.0, 0.0], [0.1, 0.0, 0.05]), atol=1e-12)
    # After the last node there is nothing to spread: node pose composed with the offset.
    np.testing.assert_allclose(seeds[4], se2.compose(nodes[1], offsets[4]), atol=1e-12)


def test_seed_of_a_reversed_segment_lands_on_the_optimised_segment() -> None:
    # Odometry that ignores the sign of the motion: it says +0.5 m, the graph says -0.5 m.
    nodes = np.array([[0.0, 0.0, 0.0], [-0.5, 0.0, 0.0]])
    steps = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]])
    seeds = seed_poses(nodes, steps, np.array([0, 0]), np.array([[0.0, 0.0, 0.0], [0.25, 0.0, 0.0]]))
    np.testing.assert_allclose(seeds[1], [-0.25, 0.0, 0.0], atol=1e-12)


@pytest.mark.parametrize(
    ("pose", "converged", "fitness", "rmse", "ok"),
    [
        ([0.1, 0.0, 0.0], True, 0.5, 0.03, True),
        ([0.1, 0.0, 0.0], False, 0.5, 0.03, False),
        ([0.1, 0.0, 0.0], True, 0.2, 0.03, False),
        ([0.1, 0.0, 0.0], True, 0.5, 0.09, False),
        ([0.4, 0.0, 0.0], True, 0.5, 0.03, False),
        ([0.0, 0.0, math.radians(11.0)], True, 0.5, 0.03, False),
    ],
)
def test_accept_applies_every_test(pose: list[float], converged: bool, fitness: float, rmse: float, ok: bool) -> None:
    tests = RefineTests(min_fitness=0.3, max_rmse_m=0.08, max_correction_m=0.3, max_correction_rad=math.radians(10))
    assert accept(tests, np.zeros(3), np.array(pose), converged, fitness, rmse) is ok
