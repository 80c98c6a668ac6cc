"""The velocity guess scaled by elapsed time (``track_velocity_time_scaled``): the ratio's edge cases, the scaled
motion's numbers, the mapper passing each scan's stamp, and the config's validation (which guesses the tracker tries
with it: ``test_gtsam_graph_velocity_guess.py``)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from pydantic import ValidationError

from albot1.data.model import Frame, Scan
from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.mapper import GtsamGraphMapper
from albot1.methods.baselines.gtsam_graph.velocity_time import elapsed, scaled_velocity, time_ratio
from albot1.methods.registry import resolve_config


def _config(**changes: object) -> GtsamGraphConfig:
    base = resolve_config("gtsam-graph", "default", {})
    assert isinstance(base, GtsamGraphConfig)
    return GtsamGraphConfig.model_validate({**base.model_dump(), **changes})


def test_the_ratio_is_the_elapsed_times_clamped_and_one_where_a_stamp_says_nothing() -> None:
    assert time_ratio(0.3, 0.1, 10.0) == pytest.approx(3.0)
    assert time_ratio(0.1, 0.4, 10.0) == 0.25
    assert time_ratio(50.0, 1.0, 10.0) == 10.0  # a clock that jumps (csail-corrected: 10000 s)
    assert time_ratio(1.0, 4294967296.0, 10.0) == 0.1  # ... or wraps around 2**32 (infinite-corridor-corrected)
    for dt_now, dt_last in [(1.0, 0.0), (0.0, 1.0), (0.0, 0.0), (1.0, -0.5), (-0.9, 0.1), (math.nan, 1.0),
                            (1.0, math.nan), (math.inf, 1.0), (1.0, math.inf), (1.0, -0.0)]:  # fmt: skip
        assert time_ratio(dt_now, dt_last, 10.0) == 1.0, (dt_now, dt_last)
    assert time_ratio(1e-300, 1e-300, 10.0) == 1.0
    assert time_ratio(1.0, 1e-300, 10.0) == 10.0  # a retimed 1 us step: clamped, never a division blow-up
    assert time_ratio(2.0, 1.0, 1.0) == 1.0  # max_ratio 1: the per-scan guess
    assert math.isnan(elapsed(None, 1.0)) and math.isnan(elapsed(1.0, None))
    assert elapsed(5.5, 2.0) == 3.5


def test_the_scaled_velocity_is_the_last_motion_repeated_over_the_elapsed_time() -> None:
    motion = np.array([0.2, 0.0, 0.1])
    thrice = se2.compose(motion, se2.compose(motion, motion))
    assert np.allclose(scaled_velocity(motion, 0.3, 0.1, 10.0), thrice, atol=1e-15)
    # 0.2 m along headings 0, 0.1, 0.2 rad: x = 0.2 (1 + cos 0.1 + cos 0.2), y = 0.2 (sin 0.1 + sin 0.2)
    assert np.allclose(thrice, [0.59501415, 0.05970055, 0.3], atol=1e-8)
    # duplicate stamps: unchanged, bit for bit
    assert scaled_velocity(motion, 0.0, 0.0, 10.0).tobytes() == motion.tobytes()
    assert scaled_velocity(motion, 0.1, 0.0, 10.0).tobytes() == motion.tobytes()


def test_the_mapper_hands_each_scan_s_stamp_to_the_tracker(monkeypatch: pytest.MonkeyPatch) -> None:
    mapper = GtsamGraphMapper(_config())
    seen: list[tuple[float | None, float | None]] = []
    step = mapper.front.step

    def record(odometry: np.ndarray, points: np.ndarray, stamp: float | None = None) -> Any:
        seen.append((stamp, mapper.front.last_stamp))
        return step(odometry, points, stamp)

    monkeypatch.setattr(mapper.front, "step", record)
    angles = np.radians(np.linspace(-90.0, 90.0, 181))
    for i, stamp in enumerate([10.0, 10.5, 11.25]):
        scan = Scan(np.full(181, 3.0), angles, stamp, 30.0)
        mapper.process(Frame(i, scan, np.array([0.05 * i, 0.0, 0.0]), None))
    assert seen == [(10.5, 10.0), (11.25, 10.5)]
    assert mapper.front.last_stamp == 11.25


def test_config_refuses_a_time_scale_with_no_velocity_guess_and_a_ratio_below_one() -> None:
    with pytest.raises(ValidationError, match="track_velocity_time_scaled needs track_scans = true"):
        _config(track_velocity_time_scaled=True, track_velocity_guess=False)
    with pytest.raises(ValidationError, match="track_velocity_time_scaled needs"):
        _config(track_velocity_time_scaled=True, track_scans=False)
    with pytest.raises(ValidationError, match="track_velocity_max_time_ratio"):
        _config(track_velocity_max_time_ratio=0.5)
    assert _config(track_velocity_time_scaled=False, track_velocity_guess=False).track_velocity_time_scaled is False


def test_the_shipped_preset_leaves_the_guess_per_scan() -> None:
    """Measured and not adopted (docs/baselines.md, gtsam-graph, "the velocity guess scaled by elapsed time")."""
    cfg = resolve_config("gtsam-graph", "default", {})
    assert isinstance(cfg, GtsamGraphConfig)
    assert cfg.track_velocity_time_scaled is False
    assert cfg.track_velocity_max_time_ratio == 10.0
