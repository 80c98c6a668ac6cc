"""Loop-closure front-end: candidate gating and the acceptance tests, on hand-made numbers."""

from __future__ import annotations

import math

import numpy as np

from albot1.methods.baselines.gtsam_graph.loop_closure import (
    Confirmer,
    LoopMatch,
    LoopTests,
    find_candidates,
    search_radius,
    verify,
)
from albot1.methods.baselines.gtsam_graph.registration import Registration

TESTS = LoopTests(
    min_fitness=0.5,
    max_rmse_m=0.05,
    max_correction_m=1.0,
    max_correction_rad=math.radians(20),
    min_sigma_ratio=0.2,
    confirmations=2,
    agreement_m=0.3,
    agreement_rad=math.radians(5),
)
INFO = np.diag([1e4, 1e4, 1e5])


def reg(
    pose: tuple[float, float, float] = (0.1, 0.0, 0.0),
    fitness: float = 0.9,
    rmse: float = 0.02,
    converged: bool = True,
    info: np.ndarray = INFO,
) -> Registration:
    return Registration(
        pose=np.array(pose),
        converged=converged,
        iterations=5,
        fitness=fitness,
        rmse_m=rmse,
        inliers=100,
        information=info,
    )


def test_candidates_exclude_recent_nodes_and_far_nodes() -> None:
    positions = np.array([[0.0, 0.0], [5.0, 0.0], [0.5, 0.0], [0.2, 0.1], [0.1, 0.0]])
    # Node 4 searches with a gap of 2: nodes 3 and 4 are too recent, node 1 is too far.
    assert find_candidates(positions, 4, radius_m=1.0, min_gap=2, max_candidates=5, separation=1) == [0, 2]
    assert find_candidates(positions, 4, radius_m=1.0, min_gap=5, max_candidates=5, separation=1) == []


def test_candidates_are_distinct_places_nearest_first() -> None:
    positions = np.array([[0.3, 0.0], [0.2, 0.0], [0.1, 0.0], [2.0, 0.0], [0.0, 0.0]])
    assert find_candidates(positions, 4, radius_m=5.0, min_gap=1, max_candidates=2, separation=2) == [2, 0]


def test_search_radius_grows_with_path_and_is_capped() -> None:
    assert search_radius(3.0, 0.05, 8.0, 0.0) == 3.0
    assert search_radius(3.0, 0.05, 8.0, 40.0) == 5.0
    assert search_radius(3.0, 0.05, 8.0, 1000.0) == 8.0


def test_verify_accepts_a_good_match() -> None:
    cov, reason = verify(reg(), np.zeros(3), TESTS, np.zeros((3, 3)))
    assert reason == "" and cov is not None
    np.testing.assert_allclose(cov, np.linalg.inv(INFO))


def test_verify_names_each_failed_test() -> None:
    guess = np.zeros(3)
    assert verify(reg(converged=False), guess, TESTS, np.zeros((3, 3)))[1] == "not converged"
    assert verify(reg(fitness=0.3), guess, TESTS, np.zeros((3, 3)))[1].startswith("fitness 0.30")
    assert verify(reg(rmse=0.2), guess, TESTS, np.zeros((3, 3)))[1].startswith("rmse 0.200")
    assert (
        verify(reg(pose=(1.5, 0.0, 0.0)), guess, TESTS, np.zeros((3, 3)))[1] == "inconsistent with the current estimate"
    )
    corridor = np.diag([1.0, 1e4, 1e5])
    assert verify(reg(info=corridor), guess, TESTS, np.zeros((3, 3)))[1] == "degenerate (corridor-like) match"


def match(node: int, correction: tuple[float, float, float]) -> LoopMatch:
    return LoopMatch(node, 0, np.zeros(3), np.eye(3), np.array(correction))


def test_two_agreeing_consecutive_matches_are_needed() -> None:
    confirmer = Confirmer(TESTS)
    accepted, expired = confirmer.offer(10, [match(10, (0.5, 0.0, 0.0))], window=1)
    assert accepted == [] and expired == 0
    accepted, expired = confirmer.offer(11, [match(11, (0.6, 0.1, 0.01))], window=1)
    assert [m.current for m in accepted] == [10, 11]


def test_disagreeing_matches_expire_unconfirmed() -> None:
    confirmer = Confirmer(TESTS)
    confirmer.offer(10, [match(10, (0.5, 0.0, 0.0))], window=1)
    accepted, _ = confirmer.offer(11, [match(11, (-0.5, 0.0, 0.0))], window=1)
    assert accepted == []
    # Node 10's match may still be confirmed by node 12 (two searching nodes later), not by node 13.
    assert confirmer.offer(12, [], window=1) == ([], 0)
    accepted, expired = confirmer.offer(13, [], window=1)
    assert accepted == [] and expired == 1
    assert confirmer.flush() == 1


def test_single_confirmation_accepts_at_once() -> None:
    tests = LoopTests(**{**TESTS.__dict__, "confirmations": 1})
    accepted, _ = Confirmer(tests).offer(3, [match(3, (0.2, 0.0, 0.0))], window=1)
    assert len(accepted) == 1
