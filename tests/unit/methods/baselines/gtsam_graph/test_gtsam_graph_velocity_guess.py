"""Which guesses gtsam-graph's tracker tries, with ICP replaced by a stub whose match from the velocity guess always
fits better, so only the rules decide: the velocity guess only after a stalled odometry
(``track_velocity_only_after_stall``) and scaled by elapsed time (``track_velocity_time_scaled``); synthetic odometry
and stamps. The scaling's own numbers and config: ``test_gtsam_graph_velocity_time.py``."""

from __future__ import annotations

import math
from collections import defaultdict
from typing import Any

import numpy as np
import pytest

from albot1.methods.baselines.gtsam_graph.backend import BackEnd
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.frontend import FrontEnd
from albot1.methods.baselines.gtsam_graph.gating import odometry_stalled
from albot1.methods.baselines.gtsam_graph.registration import Registration
from albot1.methods.registry import resolve_config


def _front(monkeypatch: pytest.MonkeyPatch, **settings: object) -> tuple[FrontEnd, list[list[np.ndarray]]]:
    """A front end whose every ICP passes at its guess: the first try of a scan fits 0.8, a second (velocity) 0.9."""
    base = resolve_config("gtsam-graph", "default", {})
    assert isinstance(base, GtsamGraphConfig)
    cfg = GtsamGraphConfig.model_validate({**base.model_dump(), **settings})
    counters: defaultdict[str, int] = defaultdict(int)
    back = BackEnd(cfg, counters)
    monkeypatch.setattr(back, "local_map", lambda: None)
    front = FrontEnd(cfg, back, counters)
    tried: list[list[np.ndarray]] = []

    def attempt(target: Any, points: Any, guess: np.ndarray, *rest: Any) -> tuple[Registration, bool, bool]:
        tried[-1].append(guess)
        fitness = 0.8 if len(tried[-1]) == 1 else 0.9
        return Registration(guess.copy(), True, 3, fitness, 0.01, 100, np.eye(3)), True, False

    monkeypatch.setattr(front, "attempt", attempt)
    return front, tried


def _drive(
    front: FrontEnd,
    tried: list[list[np.ndarray]],
    odometry: list[tuple[float, float, float]],
    stamps: list[float] | None = None,
) -> list[list[np.ndarray]]:
    """Feed the odometry readings (at ``stamps``, else unstamped; no node is made); the guesses of each later scan."""
    times: list[float | None] = list(stamps) if stamps is not None else [None] * len(odometry)
    front.last_odometry, front.last_stamp = np.asarray(odometry[0], dtype=float), times[0]
    for reading, stamp in zip(odometry[1:], times[1:], strict=True):
        tried.append([])
        pose, _ = front.step(np.asarray(reading, dtype=float), np.zeros((0, 2)), stamp)
        front.track = pose
        front.last_odometry, front.last_stamp = np.asarray(reading, dtype=float), stamp
    return tried


def _counts(tried: list[list[np.ndarray]]) -> list[int]:
    return [len(t) for t in tried]


# mit-csail's pattern: moving, the odometry repeated twice (a stall), then a catch-up jump with what it missed.
STALLED = [(0.0, 0.0, 0.0), (0.2, 0.0, 0.0), (0.4, 0.0, 0.0), (0.4, 0.0, 0.0), (0.4, 0.0, 0.0), (1.0, 0.0, 0.0)]
# A moving odometry that turns 20 deg on the last scan: the last tracked motion (straight) disagrees with it.
MOVING = [(0.0, 0.0, 0.0), (0.2, 0.0, 0.0), (0.4, 0.0, 0.0), (0.6, 0.0, math.radians(20.0))]


@pytest.mark.parametrize("only_after_stall", [True, False])
def test_a_stalled_then_jumping_odometry_still_gets_the_velocity_guess(
    only_after_stall: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    front, tried = _front(monkeypatch, track_velocity_only_after_stall=only_after_stall)
    # Tried on both stalled scans and on the catch-up (the scan after a repeat), not while the two guesses agree.
    assert _counts(_drive(front, tried, STALLED)) == [1, 1, 2, 2, 2]
    assert front.counters["tracking_velocity_guess"] == 3
    # The velocity matches carried the tracked pose through the stall: the catch-up lands where the robot is.
    assert np.allclose(front.track, [1.0, 0.0, 0.0])


def test_a_moving_odometry_gets_no_velocity_guess_with_the_rule_and_one_without(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    front, tried = _front(monkeypatch, track_velocity_only_after_stall=True)
    assert _counts(_drive(front, tried, MOVING)) == [1, 1, 1]
    assert front.counters["tracking_velocity_guess"] == 0
    assert np.allclose(front.track, MOVING[-1])
    front, tried = _front(monkeypatch, track_velocity_only_after_stall=False)
    assert _counts(_drive(front, tried, MOVING)) == [1, 1, 2]
    assert front.counters["tracking_velocity_guess"] == 1


def test_a_stall_is_an_exactly_repeated_reading_not_a_small_or_translation_only_one() -> None:
    zero, moving = np.zeros(3), np.array([0.2, 0.0, 0.0])
    assert odometry_stalled(zero, moving)
    assert odometry_stalled(moving, zero)  # the catch-up step
    assert odometry_stalled(-0.0 * moving, None)  # -0.0 is a repeat too (se2.between of equal poses can give it)
    assert not odometry_stalled(moving, moving)
    assert not odometry_stalled(moving, None)
    assert not odometry_stalled(np.array([1e-12, 0.0, 0.0]), moving)
    # An in-place turn reports exactly zero translation (intel, fr079): it is no stall.
    assert not odometry_stalled(np.array([0.0, 0.0, 0.05]), np.array([0.0, 0.0, 0.05]))


def test_the_shipped_preset_keeps_the_velocity_guess_on_every_disagreement() -> None:
    """Measured and not adopted (docs/baselines.md, gtsam-graph, "the velocity guess only after a stall")."""
    cfg = resolve_config("gtsam-graph", "default", {})
    assert isinstance(cfg, GtsamGraphConfig)
    assert cfg.track_velocity_guess is True
    assert cfg.track_velocity_only_after_stall is False


# 0.2 m per second, then two scans dropped: the last step is 0.6 m over 3 s (the odometry, perfect, says so).
DROPPED = [(0.0, 0.0, 0.0), (0.2, 0.0, 0.0), (0.4, 0.0, 0.0), (1.0, 0.0, 0.0)]
DROPPED_STAMPS = [0.0, 1.0, 2.0, 5.0]


def test_after_dropped_scans_the_time_scaled_guess_agrees_with_the_odometry_and_no_slide_is_tried(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    front, tried = _front(monkeypatch, track_velocity_time_scaled=False)
    last = _drive(front, tried, DROPPED, DROPPED_STAMPS)[-1]
    assert len(last) == 2 and np.allclose(last[1], [0.6, 0.0, 0.0])  # per scan: 0.4 m short of the odometry
    front, tried = _front(monkeypatch, track_velocity_time_scaled=True)
    last = _drive(front, tried, DROPPED, DROPPED_STAMPS)[-1]
    assert len(last) == 1 and np.allclose(last[0], [1.0, 0.0, 0.0])  # 3 s at 0.2 m/s: the odometry's own guess
    assert front.counters["tracking_velocity_guess"] == 0
    assert front.counters["tracking_velocity_time_scaled"] == 1


@pytest.mark.parametrize(
    "stamps",
    [[0.0, 0.0, 0.0, 0.0], [0.0, 1.0, 1.0, 4.0], [0.0, 1.0, 2.0, 1.5], [0.0, 1.0, 2.0, 2.0], [math.nan] * 4],
    ids=["all-zero", "duplicate-then-jump", "backwards", "duplicate-last", "unknown"],
)
def test_stamps_that_say_nothing_leave_the_per_scan_guess_as_with_the_setting_off(
    stamps: list[float], monkeypatch: pytest.MonkeyPatch
) -> None:
    front, tried = _front(monkeypatch, track_velocity_time_scaled=False)
    off = _drive(front, tried, DROPPED, stamps)
    front, tried = _front(monkeypatch, track_velocity_time_scaled=True)
    on = _drive(front, tried, DROPPED, stamps)
    assert [[g.tobytes() for g in scan] for scan in on] == [[g.tobytes() for g in scan] for scan in off]
    assert "tracking_velocity_time_scaled" not in front.counters
