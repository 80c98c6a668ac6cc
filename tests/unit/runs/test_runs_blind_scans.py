"""A run whose scans mostly have no return (every range NaN: a driver's range_max below every reading, REP 117's
+inf) still succeeds, on the odometry alone, and now says so in one warning instead of passing for a scan matcher
that agreed with the odometry."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from albot1.data.model import Frame, Scan, Sequence
from albot1.runs.execute import blind_note, run_method

ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 9)


def _sequence(blind: int, n: int = 6) -> Sequence:
    frames = [
        Frame(
            i,
            Scan(np.full(9, np.nan) if i < blind else np.full(9, 2.0), ANGLES, float(i), 30.0),
            np.array([0.5 * i, 0.0, 0.0]),
        )
        for i in range(n)
    ]
    return Sequence.from_frames("toy", frames)


def _warnings(blind: int, caplog: pytest.LogCaptureFixture) -> list[str]:
    with caplog.at_level(logging.WARNING, logger="albot1.runs.execute"):
        result = run_method("gtsam-graph", _sequence(blind))
    assert result.poses.shape == (6, 3) and np.isfinite(result.poses).all()
    return [r.getMessage() for r in caplog.records if r.name == "albot1.runs.execute"]


def test_a_run_without_a_single_return_says_it_followed_the_odometry(caplog: pytest.LogCaptureFixture) -> None:
    assert _warnings(6, caplog) == [
        "gtsam-graph on toy: none of the 6 scans had a return (every range NaN, infinite or outside the scanner's "
        "limits); in those the method had only the odometry to go by"
    ]


def test_half_the_scans_blind_is_counted(caplog: pytest.LogCaptureFixture) -> None:
    assert _warnings(3, caplog) == [
        "gtsam-graph on toy: 3 of the 6 scans had no return (every range NaN, infinite or outside the scanner's "
        "limits); in those the method had only the odometry to go by"
    ]


def test_fewer_than_half_blind_says_nothing(caplog: pytest.LogCaptureFixture) -> None:
    assert _warnings(2, caplog) == []


def test_blind_note_of_an_empty_run_is_none() -> None:
    assert blind_note(0, 0, "odometry", "toy") is None
