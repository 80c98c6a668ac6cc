"""Edges spanning runs of node steps: odometry run factors (OdometryRuns) and span matches (span_edges)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.odometry_runs import OdometryRuns
from albot1.methods.baselines.gtsam_graph.odometry_trust import UNTRUSTED_VARIANCE, OdometryTrust
from albot1.methods.baselines.gtsam_graph.span_edges import span_guess, span_target_nodes
from albot1.methods.registry import resolve_config

STEP = np.array([0.5, 0.02, math.radians(3.0)])  # one node step of odometry, previous node's frame
DEG2 = math.radians(1.0) ** 2
MATCH_COV = np.diag([0.02**2, 0.02**2, 0.25 * DEG2])  # the match floor of the default preset, (0.5 deg)^2
TWO_STEPS = se2.compose(STEP, STEP)


def _runs(ratio: float = 1.0) -> OdometryRuns:
    """Runs of two steps, heading only: 40 runs before anything can be judged (min_history(3) = 40)."""
    trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=(2,), bias_horizon=50, min_variance_ratio=ratio)
    return OdometryRuns(trust, 2)


def _turned(deg: float) -> np.ndarray:
    return STEP + np.array([0.0, 0.0, math.radians(deg)])


def _feed(runs: OdometryRuns, n_runs: int, run_error_deg: float = 0.3, bias_deg: float = 0.0) -> list[list[object]]:
    """``n_runs`` runs of two matched steps from node 1 on: the first step's match off by ``bias_deg`` +-
    ``run_error_deg`` (alternating), the second exact; what each add returned."""
    out = []
    for r in range(n_runs):
        sign = 1.0 if r % 2 else -1.0
        out.append(list(runs.add(2 * r + 1, STEP, _turned(bias_deg + sign * run_error_deg), MATCH_COV)))
        out.append(list(runs.add(2 * r + 2, STEP, STEP, MATCH_COV)))
    return out


def test_runs_are_judged_once_forty_are_known_and_span_their_two_steps_with_the_floored_heading_variance() -> None:
    runs = _runs()
    returned = _feed(runs, 40)
    assert all(r == [] for r in returned[:-1])
    edges = returned[-1]
    assert len(edges) == 40
    for r, edge in enumerate(edges):
        assert edge.first == 2 * r and edge.key == 2 * r + 2  # type: ignore[attr-defined]
        assert edge.relative == pytest.approx(TWO_STEPS)  # type: ignore[attr-defined]
        # spread (1.4826 x 0.3 deg)^2 = 0.198 deg^2 is below the chain's stated 2 x 0.25 deg^2: the odometry is the
        # better side, and the floor (ratio 1) puts it at the chain's variance
        assert edge.covariance == pytest.approx(  # type: ignore[attr-defined]
            np.diag([UNTRUSTED_VARIANCE, UNTRUSTED_VARIANCE, 0.5 * DEG2])
        )
    # after that, one factor per completed run and nothing in between
    assert list(runs.add(81, STEP, STEP, MATCH_COV)) == []  # a run of no error keeps the median at 0
    (edge,) = runs.add(82, STEP, STEP, MATCH_COV)
    assert (edge.first, edge.key) == (80, 82)


def test_without_the_floor_the_run_gets_its_earned_variance() -> None:
    edges = _feed(_runs(ratio=0.0), 40)[-1]
    earned = (1.4826 * 0.3) ** 2 * DEG2 * math.sqrt(2.0 / 40)  # the sampling floor of 40 runs; median 0: no bias
    assert edges[0].covariance[2, 2] == pytest.approx(earned)  # type: ignore[attr-defined]


def test_a_steady_run_error_is_a_bias_and_gets_no_factor() -> None:
    # 0.3 +- 0.1 deg: the median 0.3 deg stands 0.3 / (1.2533 x 0.148 / sqrt(40)) = 10 standard errors from 0
    assert all(r == [] for r in _feed(_runs(), 45, run_error_deg=0.1, bias_deg=0.3))


def test_a_step_without_a_match_ends_the_run_and_the_next_run_starts_after_it() -> None:
    runs = _runs()
    _feed(runs, 40)
    assert list(runs.add(81, STEP, STEP, MATCH_COV)) == []
    runs.reset()  # node 82 fell back to odometry
    assert list(runs.add(83, STEP, STEP, MATCH_COV)) == []
    (edge,) = runs.add(84, STEP, STEP, MATCH_COV)
    assert (edge.first, edge.key) == (82, 84)


def test_runs_holding_a_step_that_turns_beyond_the_limit_are_left_out() -> None:
    trust = OdometryTrust(50, bias_z=3.0, gate_chi2=16.27, components=(2,), bias_horizon=50, min_variance_ratio=1)
    runs = OdometryRuns(trust, 2, max_turn_rad=math.radians(2.0))  # STEP turns 3 deg: every run here is left out
    assert all(r == [] for r in _feed(runs, 45))
    straight = np.array([0.5, 0.02, math.radians(1.0)])
    for r in range(40):  # the same innovations on steps turning 1 deg: judged once 40 are known, as without the limit
        sign = 1.0 if r % 2 else -1.0
        first = runs.add(100 + 2 * r, straight, straight + np.array([0.0, 0.0, math.radians(sign * 0.3)]), MATCH_COV)
        second = runs.add(101 + 2 * r, straight, straight, MATCH_COV)
        assert list(first) == []
    assert len(second) == 40


def test_span_matches_target_the_nodes_ending_span_back_and_start_from_the_sequential_chain() -> None:
    assert span_target_nodes(10, 5, 3) == range(3, 6)
    assert span_target_nodes(10, 5, 10) == range(0, 6)
    assert span_target_nodes(4, 5, 3) == range(0)  # node 4 - 5 does not exist
    estimates = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, math.pi / 2], [1.0, 1.0, math.pi / 2]])
    # the new node, 0.5 m ahead of node 2 (facing +y), is at (1, 1.5) facing +y: in node 0's frame, the same
    assert span_guess(estimates, 0, 2, np.array([0.5, 0.0, 0.0])) == pytest.approx([1.0, 1.5, math.pi / 2])


def test_both_are_off_in_the_preset_and_refuse_settings_that_would_do_nothing() -> None:
    cfg = resolve_config("gtsam-graph", "default", {})
    assert isinstance(cfg, GtsamGraphConfig)
    assert cfg.odometry_trust_run_nodes == 0 and cfg.span_nodes == 0
    base = cfg.model_dump()
    with pytest.raises(ValidationError, match="odometry_trust_run_nodes = 1"):
        GtsamGraphConfig.model_validate({**base, "odometry_trust_run_nodes": 1})
    with pytest.raises(ValidationError, match="odometry_trust_run_nodes needs"):
        GtsamGraphConfig.model_validate({**base, "odometry_trust_run_nodes": 2, "odometry_trust_factors": False})
    with pytest.raises(ValidationError, match="span_nodes = 1"):
        GtsamGraphConfig.model_validate({**base, "span_nodes": 1})
