"""A third-party method that misbehaves fails its run with one line naming it; it never alters the run's record.

The mapper here is registered as a plugin would be (error class
``PluginMethodError``); each mode is one way a plugin found in the wild, or
written in a hurry, breaks the contract of :mod:`albot1.contract`.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Iterator
from typing import Any, ClassVar

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict

from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame, Scan, Sequence
from albot1.methods import registry as methods
from albot1.methods.errors import PluginMethodError
from albot1.methods.plugins import PLUGIN_ERROR_CLASS
from albot1.methods.registry import MethodRegistry, MethodSpec
from albot1.runs.execute import run_method

ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 9)
ANGLES.setflags(write=False)  # as the loaders share them
SCANS = 6
RUN = "rogue on toy"


def _sequence() -> Sequence:
    """An in-memory sequence: its frames are the same objects on every pass (as a library user's would be)."""
    frames = [
        Frame(i, Scan(np.full(9, 2.0), ANGLES, float(i), 30.0), np.array([0.5 * i, 0.1 * i, 0.0])) for i in range(SCANS)
    ]
    return Sequence.from_frames("toy", frames)


class RogueConfig(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    mode: str = "ok"


class RogueMapper:
    """Dead reckoning that breaks the contract in the way ``mode`` names."""

    name: ClassVar[str] = "rogue"
    config_model: ClassVar[type[BaseModel]] = RogueConfig
    presets: ClassVar[dict[str, dict[str, Any]]] = {"default": {}}

    def __init__(self, config: RogueConfig, *, seed: int = 0) -> None:
        self.mode = config.mode
        self.poses: list[np.ndarray] = []
        if self.mode == "init-raise":
            raise RuntimeError("no licence")
        if self.mode == "init-exit":
            sys.exit(0)

    def warm_up(self, announce: Any = None) -> None:
        if self.mode == "warm-exit":
            sys.exit(3)

    def process(self, frame: Frame) -> None:
        self.poses.append(np.array(frame.odometry))
        if self.mode == "mutate":  # writes into its input: clips every range, zeroes the odometry
            frame.scan.ranges[:] = np.nan
            frame.odometry[:] = 0.0
        if frame.index == 2:
            if self.mode == "exit":
                sys.exit(0)
            if self.mode == "base":
                raise BaseException("stop")
            if self.mode == "interrupt":
                raise KeyboardInterrupt

    def finish(self) -> Any:
        poses: Any = np.asarray(self.poses)
        counters: Any = {"views": len(self.poses), "updates": 1}
        map_data: Any = MapData(points=np.zeros((1, 2)))
        if self.mode == "finish-exit":
            sys.exit(0)
        if self.mode == "none":
            return None
        if self.mode == "huge":
            poses[3, 0] = 1e300
        if self.mode == "complex":
            poses = poses + 1j
        if self.mode == "text":
            poses = poses.astype(str)
        if self.mode == "ragged":
            poses = [[0.0, 0.0, 0.0]] * (len(self.poses) - 1) + [[0.0, 0.0]]
        if self.mode == "no-map":
            map_data = None
        if self.mode == "points-xyz":  # stored as points_text's (-1, 2) rows: three points out of two
            map_data = MapData(points=np.arange(6.0).reshape(2, 3))
        if self.mode == "points-flat":
            map_data = MapData(points=np.zeros(4))
        if self.mode == "segments-text":
            map_data = MapData(segments=np.array([["0", "0", "1", "x"]]))
        if self.mode == "short-properties":  # map.geojson paired them with zip: the third segment was dropped
            map_data = MapData(segments=np.zeros((3, 4)), segment_properties=[{"id": 0}, {"id": 1}])
        if self.mode == "points-complex":
            map_data = MapData(points=np.zeros((2, 2)) + 1j)
        if self.mode == "nan-counter":
            counters["updates"] = float("nan")
        return MapperOutput(poses=poses, map=map_data, counters=counters)


@pytest.fixture
def rogue() -> MethodRegistry:
    """The process's registry plus ``rogue``, declared as an installed plugin's method is."""
    spec = MethodSpec("rogue", f"{__name__}:RogueMapper", error_class=PLUGIN_ERROR_CLASS, plugin="rogue-slam 0.1")
    return methods.method_registry().with_methods(spec)


@pytest.mark.parametrize(
    ("mode", "message"),
    [
        (
            "huge",
            f"{RUN}: 1 poses beyond 1e+08 m, first at scan 3 ([1e+300, 0.30000000000000004, 0.0]); "
            "expected positions of a map in metres (diverged)",
        ),
        (
            "complex",
            f"{RUN}: the poses are of dtype complex128; expected {SCANS} poses (one per scan) of "
            "(x, y, theta) as real numbers",
        ),
        (
            "text",
            f"{RUN}: the poses are of dtype <U32; expected {SCANS} poses (one per scan) of (x, y, theta) "
            "as real numbers",
        ),
        (
            "ragged",
            f"{RUN}: the poses do not form an array (rows of unequal length?); expected {SCANS} poses "
            "(one per scan) of (x, y, theta) as real numbers",
        ),
        ("none", f"{RUN}: finish() returned NoneType; expected a MapperOutput (albot1.contract)"),
        ("no-map", f"{RUN}: the map is NoneType; expected a MapData (albot1.contract)"),
        ("points-xyz", f"{RUN}: the map's points are of shape (2, 3); expected (K, 2) rows (x, y) of real numbers"),
        ("points-flat", f"{RUN}: the map's points are of shape (4,); expected (K, 2) rows (x, y) of real numbers"),
        (
            "segments-text",
            f"{RUN}: the map's segments are of dtype <U1; expected (M, 4) rows (x1, y1, x2, y2) of real numbers",
        ),
        (
            "short-properties",
            f"{RUN}: the map has 2 segment properties for 3 segments; expected one dict per segment (or none)",
        ),
        (
            "points-complex",
            f"{RUN}: the map's points are of dtype complex128; expected (K, 2) rows (x, y) of real numbers",
        ),
        ("nan-counter", f"{RUN}: counter 'updates' is nan; expected a finite number"),
    ],
)
def test_an_output_no_metric_can_score_fails_the_run_in_one_line(
    rogue: MethodRegistry, mode: str, message: str
) -> None:
    assert _failure(rogue, mode) == message


def _failure(rogue: MethodRegistry, mode: str) -> str:
    """The one line of the PluginMethodError a run of the rogue method in ``mode`` fails with."""
    with pytest.raises(PluginMethodError) as caught:
        run_method("rogue", _sequence(), overrides={"mode": mode}, registry=rogue)
    return str(caught.value)


EXPECTED_RETURN = "expected it to return, or to raise an exception for a failure (a method may not end the process)"


@pytest.mark.parametrize(
    ("mode", "message"),
    [
        ("exit", f"{RUN} failed at scan 2: it raised SystemExit(0) (sys.exit); {EXPECTED_RETURN}"),
        ("init-exit", f"{RUN} failed while starting: it raised SystemExit(0) (sys.exit); {EXPECTED_RETURN}"),
        ("warm-exit", f"{RUN} failed while starting: it raised SystemExit(3) (sys.exit); {EXPECTED_RETURN}"),
        ("finish-exit", f"{RUN} failed in finish: it raised SystemExit(0) (sys.exit); {EXPECTED_RETURN}"),
        ("base", f"{RUN} failed at scan 2: it raised BaseException: stop; {EXPECTED_RETURN}"),
        ("init-raise", f"{RUN} failed while starting: RuntimeError: no licence"),
    ],
)
def test_a_method_that_ends_the_process_or_fails_to_start_is_a_failed_run(
    rogue: MethodRegistry, mode: str, message: str
) -> None:
    """``sys.exit(0)`` inside a method once ended `albot1 run` with exit 0 and no run; now it is the method's error."""
    assert _failure(rogue, mode) == message


def test_ctrl_c_still_stops_the_run(rogue: MethodRegistry) -> None:
    with pytest.raises(KeyboardInterrupt):
        run_method("rogue", _sequence(), overrides={"mode": "interrupt"}, registry=rogue)


def test_a_method_writing_into_its_frames_alters_neither_the_record_nor_the_sequence(
    rogue: MethodRegistry, caplog: pytest.LogCaptureFixture
) -> None:
    sequence = _sequence()
    honest = run_method("rogue", sequence, degradation="gauss:0.05:1", seed=1, registry=rogue)
    with caplog.at_level(logging.WARNING):
        mutated = run_method(
            "rogue", sequence, overrides={"mode": "mutate"}, degradation="gauss:0.05:1", seed=1, registry=rogue
        )
    np.testing.assert_array_equal(mutated.odometry, honest.odometry)
    np.testing.assert_array_equal(mutated.poses, honest.poses)  # the method saw the degraded odometry intact
    assert "had no return" not in caplog.text  # the scans had returns: the method blanked its own copies
    for frame in sequence.frames():  # the sequence's own frames are as they were
        np.testing.assert_array_equal(frame.scan.ranges, np.full(9, 2.0))
        np.testing.assert_array_equal(frame.odometry, [0.5 * frame.index, 0.1 * frame.index, 0.0])


def test_a_failure_reading_the_next_scan_is_not_the_method_s(rogue: MethodRegistry) -> None:
    """The loader failing on scan 3 read "rogue on toy failed at scan 2: OSError: ...": the method blamed, scan wrong.

    The error is the data's: it leaves the run as raised (the bench records it, `albot1 run` says it in one line).
    """
    frames = list(_sequence().frames())

    def reading() -> Iterator[Frame]:
        yield from frames[:3]
        raise OSError(5, "Input/output error", "toy.bag")

    with pytest.raises(OSError) as caught:
        run_method("rogue", Sequence("toy", reading), registry=rogue)
    assert type(caught.value) is OSError
    assert (caught.value.errno, caught.value.filename) == (5, "toy.bag")
