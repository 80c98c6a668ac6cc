"""Non-finite and absurd values in logs and degraded odometry are refused with their location."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.contract import MapData
from albot1.data.convert import convert
from albot1.data.degrade import degrade
from albot1.data.errors import DataError
from albot1.data.finite import frame_problem, pose_problem
from albot1.data.model import Frame, Scan
from albot1.data.open import open_sequence
from albot1.runs.execute import map_problem

WORLD = "synthetic-corridor[:20]"


def _frame(odometry: list[float], reference: list[float] | None = None, t: float = 1.0) -> Frame:
    scan = Scan(np.ones(3), np.array([-0.1, 0.0, 0.1]), t, 10.0)
    return Frame(0, scan, np.asarray(odometry, float), None if reference is None else np.asarray(reference, float))


@pytest.mark.parametrize(
    ("frame", "problem"),
    [
        (_frame([1e308, 0, 0]), "odometry position (1e+308, 0) m is beyond 1e+08 m"),
        (_frame([0, float("nan"), 0]), "odometry (0, nan, 0) is not finite"),
        (_frame([0, 0, float("inf")]), "odometry (0, 0, inf) is not finite"),
        (_frame([0, 0, 0], [0, -2e9, 0]), "reference pose position (0, -2e+09) m is beyond"),
        (_frame([0, 0, 0], t=float("inf")), "timestamp inf is not finite"),
    ],
)
def test_frame_problems_are_named(frame: Frame, problem: str) -> None:
    found = frame_problem(frame)
    assert found is not None and found.startswith(problem)


def test_a_reading_a_huge_max_range_lets_through_is_named_and_no_return_is_not() -> None:
    """A ROBOTLASER1 line may declare 1e31 m: a kept 1e30 m reading is refused at its scan, NaN (no return) is not."""
    far = Frame(0, Scan(np.array([1.0, 1e30, np.nan]), np.array([-0.1, 0.0, 0.1]), 1.0, 1e31), np.zeros(3))
    assert frame_problem(far) == (
        "range 2 of 3 is 1e+30 m (max range 1e+31 m), expected at most 1e+08 m: no laser measures farther"
    )
    near = Frame(0, Scan(np.array([1.0, 5e7, np.nan]), np.array([-0.1, 0.0, 0.1]), 1.0, float("inf")), np.zeros(3))
    assert frame_problem(near) is None


def test_a_good_frame_has_no_problem() -> None:
    assert frame_problem(_frame([1e7, -1e7, 3.0], [0, 0, -3.0])) is None
    assert pose_problem([1.0, 2.0, 3.0], "x") is None


@pytest.mark.parametrize("fmt", ["carmen", "ros1", "ros2-mcap", "albot-log"])
def test_a_log_with_an_absurd_odometry_is_refused_at_that_scan(tmp_path: Path, fmt: str) -> None:
    sequence = open_sequence(WORLD)
    bad = sequence.with_frames(
        lambda frames: (
            Frame(f.index, f.scan, np.array([1e300, 0.0, 0.0]) if f.index == 7 else f.odometry, f.reference)
            for f in frames
        )
    )
    out = tmp_path / {"carmen": "w.clf", "ros1": "w.bag", "ros2-mcap": "w2", "albot-log": "w.albotlog"}[fmt]
    convert(bad, out, fmt)  # the writers store what they are given; the reader refuses it
    options = "?odometry=odom" if fmt == "carmen" else ""
    with pytest.raises(DataError, match=r"scan 7 \(t = .* s\): odometry position \(1e\+300, .*\) m is beyond 1e\+08 m"):
        open_sequence(f"{out}{options}").arrays  # noqa: B018


@pytest.mark.parametrize("stamp", [1e300, 1.7e18, -2e11])
def test_a_log_stamped_beyond_the_trajectory_files_bound_is_refused_when_loaded(tmp_path: Path, stamp: float) -> None:
    """A stamp in nanoseconds (or 1e300) used to load and run; the run's own trajectory.tum was then refused
    by ``albot1 evaluate`` ("timestamp ... is beyond 1e+11"): the log is refused at that scan instead."""
    sequence = open_sequence(WORLD)
    bad = sequence.with_frames(
        lambda frames: (
            Frame(f.index, Scan(f.scan.ranges, f.scan.angles, stamp, f.scan.max_range), f.odometry, f.reference)
            if f.index == 4
            else f
            for f in frames
        )
    )
    out = tmp_path / "w.albotlog"
    convert(bad, out, "albot-log")
    with pytest.raises(
        DataError, match=r"w\.albotlog: scan 4 \(t = .* s\): timestamp .* is beyond 1e\+11; expected seconds"
    ):
        open_sequence(str(out)).arrays  # noqa: B018


def test_stamps_of_todays_unix_time_and_negative_ones_pass() -> None:
    assert frame_problem(_frame([0, 0, 0], t=1.8e9)) is None
    assert frame_problem(_frame([0, 0, 0], t=-5.0)) is None


@pytest.mark.parametrize("spec", ["gauss:1e300:1", "bias:1e200:0"])
def test_a_degradation_that_overflows_names_the_step(spec: str) -> None:
    with pytest.raises(DataError, match=r"degradation .* seed 3, step to scan 1 \(t = .*\): the degraded odometry"):
        degrade(open_sequence(WORLD), spec, seed=3).arrays  # noqa: B018


def test_a_map_with_non_finite_points_is_refused_at_the_run_boundary() -> None:
    assert map_problem(MapData(points=np.array([[0.0, 1.0], [2.0, 3.0]]))) is None
    problem = map_problem(MapData(points=np.array([[0.0, 1.0], [np.inf, 3.0]])))
    assert problem is not None and problem.startswith("the map has 1 point(s) with non-finite or absurd")
    problem = map_problem(MapData(segments=np.array([[0.0, 1.0, 1e200, 0.0]])))
    assert problem is not None and "segment 0" in problem
