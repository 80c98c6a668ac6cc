"""The Experiment 3 world: a 96 m square corridor ring, 106 start-stop views, odometry ending 4.6 m from its start."""

from __future__ import annotations

import numpy as np
import pytest

from albot1.data.synthetic import worlds
from albot1.data.synthetic.odometry import simulate
from albot1.data.synthetic.route import START_STOP
from albot1.geometry import se2
from albot1.metrics.loop_gap import route_gap

NAME = "synthetic-square-startstop"


def test_the_route_is_the_thesis_shape_about_100_m_and_106_views() -> None:
    data = worlds.world_data(NAME)
    assert data.spec.sampling == START_STOP
    assert data.scans == 106  # the thesis's 106 views (3.2.3)
    assert data.route_length == pytest.approx(96.0)
    np.testing.assert_array_equal(data.reference[0], data.reference[-1])  # closed: the loop gap is end vs start
    steps = se2.relative_steps(data.reference)
    turns = steps[np.abs(steps[:, 2]) > 1e-9, 2]
    assert np.all(turns > 0)  # every turn to the left: a square-like loop, Figure 3.20
    assert np.degrees(turns.sum()) == pytest.approx(360.0)
    moves = np.hypot(steps[:, 0], steps[:, 1])
    assert moves.max() == pytest.approx(1.0)  # start-stop: 1 m moves, 45 deg turns
    assert np.degrees(np.abs(turns)).max() == pytest.approx(45.0)


def test_its_clean_odometry_ends_where_the_thesis_odometry_did() -> None:
    data = worlds.world_data(NAME)
    gap = route_gap(data.odometry, data.reference)
    assert gap["gap_m"] == pytest.approx(4.6, abs=0.05)  # thesis 3.2.3, Figure 3.21a: about 4.6 m
    assert gap["reference_offset_m"] == 0.0


def test_the_seed_is_a_typical_realisation_of_the_error_model() -> None:
    """The median end error of the office odometry model over seeds 100-139 on this route is also about 4.6 m."""
    data = worlds.world_data(NAME)
    gaps = [
        route_gap(simulate(data.reference, data.spec.odometry, seed=np.random.default_rng([s, 0])), data.reference)[
            "gap_m"
        ]
        for s in range(100, 140)
    ]
    median = float(np.median(gaps))
    assert abs(median - 4.6) < 0.1
    assert abs(route_gap(data.odometry, data.reference)["gap_m"] - median) < 0.1


def test_the_ring_has_door_jambs_alcoves_and_furniture() -> None:
    """Short wall pieces (jambs, alcoves, furniture) give Albot1 corners to track: the ring is not corridor C."""
    data = worlds.world_data(NAME)
    walls = data.plan.walls
    assert len(walls) > 100
    assert len(data.plan.doorways) == 13
    lengths = np.hypot(walls[:, 2] - walls[:, 0], walls[:, 3] - walls[:, 1])
    assert np.sum(lengths < 2.0) > 40
